#include "controllers/linuxcnc/component_route.hpp"

#include <algorithm>
#include <cctype>
#include <map>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/inverse_kinematics.hpp"
#include "controllers/common/controller_model.hpp"
#include "controllers/common/files.hpp"
#include "controllers/common/header.hpp"
#include "controllers/linuxcnc/config_files.hpp"
#include "controllers/linuxcnc/kins_component.hpp"
#include "controllers/linuxcnc/laser_comp.hpp"

namespace cnccomp::controllers::linuxcnc {
using namespace cnccomp::controllers::common;
namespace {

std::string lower(std::string s) {
    for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return s;
}

/// The pin of coefficient k of deviation `def`, as kins_component.hpp documents it (written here from that text, not
/// through the generator's function, so that a renamed pin shows as an unknown pin in the reader).
std::string pinOf(const DeviationDef& def, int k) {
    return def.kind == DeviationKind::Location ? "dev." + lower(def.name) : fmt::format("dev.{}.{}", lower(def.name), k);
}

std::string coordinatesOf(const MachineModel& m) {
    std::string s;
    for (const std::string& a : m.axisNames) s += a;
    return s;
}

}  // namespace

EmitResult emitComponentRoute(const EmitRequest& r) {
    const MachineModel& m = r.machine;
    EmitResult out;
    for (size_t k = 0; k < m.deviations.size(); ++k)
        if (r.deviations.present[k])
            out.compensated.push_back({m.deviations[k].name, fmt::format("exact model in the kinematics component {} (HAL pin {}.{})",
                                                                          kKinsName, kKinsName, pinOf(m.deviations[k], 0))});
    for (int a = 0; a < m.axisCount(); ++a)
        if (r.deviations.reversalPresent[static_cast<size_t>(a)])
            out.compensated.push_back({"B" + m.axisNames[static_cast<size_t>(a)],
                                       fmt::format("[JOINT_{}] BACKLASH = {} mm in {}", a,
                                                   fixed(backlashFromReversal(r.deviations.reversal[static_cast<size_t>(a)]), 6),
                                                   kKinsIniFile)});
    const std::string source = kinematicsComponent(m, r.deviations, KinsComponentOptions{});
    const std::string coordinates = coordinatesOf(m);
    std::vector<std::string> notes{
        fmt::format("route: generated kinematics component {} (the whole model: every deviation, tool tip and tool axis); build "
                    "it with halcompile --install {} (Debian package linuxcnc-uspace-dev), see README.txt",
                    kKinsName, kKinsSourceFile),
        "for LinuxCNC 2.9 (userkins.comp interface); checked against the real LinuxCNC 2.9 (Debian 12 linuxcnc-uspace)",
        fmt::format("kinematics: {} joints={} coordinates={} (joint n = letter n = machine axis n, controller machine coordinates, "
                    "mm and deg)",
                    kKinsName, m.axisCount(), coordinates),
        fmt::format("modes: switchkins-type 0 (default) joint mode: axis words = the nominal machine's commands (cnccomp "
                    "testprog's programs, G43.1 Z<tool length> with Z written minus it); switchkins-type 1 tool-tip mode: X Y Z = tool tip in workpiece coordinates"),
        "deviation pins: link values (mm, rad; component errors: basis coefficients) read back by cnccomp verify from this file"};
    const HeaderInfo h = makeHeaderInfo(r, fmt::format("LinuxCNC 2.9 (component {})", kKinsName), out, notes);

    std::string ini = formatHeader(h, "# ");
    ini += fmt::format("\n# Component route: load the generated kinematics component (README.txt)\n[KINS]\nKINEMATICS = {}\nJOINTS = {}\n"
                       "\n[TRAJ]\nCOORDINATES = {}\n",
                       kKinsName, m.axisCount(), coordinates);
    std::string hal = formatHeader(h, "# ");
    hal += fmt::format("\n# Component route: the tool length and the deviation values of {} (README.txt).\n"
                       "# To switch modes from a program: net cnccomp-kinstype motion.analog-out-03 => motion.switchkins-type,\n"
                       "# then M68 E3 Q1 (tool-tip mode) or M68 E3 Q0 (joint mode), each followed by M66 E0 L0.\n"
                       "net cnccomp-tool-offset motion.tooloffset.z => {}.tool-offset\n",
                       kKinsName, kKinsName);
    for (const DeviationDef& def : m.deviations)
        for (int k = 0; k < def.size(); ++k) {
            const double v = r.deviations.values[def.offset + k];
            hal += fmt::format("setp {}.{} {:.17g}\n", kKinsName, pinOf(def, k), v == 0.0 ? 0.0 : v);
        }
    // Reversal values → [JOINT_n] BACKLASH = −B̄ (joint n = machine axis n here; no COMP_FILE on this route): LinuxCNC 2.9
    // adds +BACKLASH/2 while the joint moves +, −BACKLASH/2 while it moves −, held at rest, after backlash_filt's ramp
    // (control.c compute_screw_comp); a negative BACKLASH (B̄ > 0) is applied with its sign (kNegativeBacklashNote). Both
    // run on the real LinuxCNC 2.9: tests/linuxcnc/test_linuxcnc_backlash.cpp.
    for (int a = 0; a < m.axisCount(); ++a) {
        if (!r.deviations.reversalPresent[static_cast<size_t>(a)]) continue;
        const double b = backlashFromReversal(r.deviations.reversal[static_cast<size_t>(a)]);
        ini += fmt::format("\n[JOINT_{}]\n# axis {}: BACKLASH = -B{} (the reversal value of the deviation set, laser_comp.hpp){}\n"
                           "BACKLASH = {}\n",
                           a, m.axisNames[static_cast<size_t>(a)], m.axisNames[static_cast<size_t>(a)],
                           b < 0 ? kNegativeBacklashNote : "",
                           fixed(b, 6));
    }
    out.files.push_back({kKinsSourceFile, source});
    out.files.push_back({kKinsIniFile, ini});
    out.files.push_back({kKinsHalFile, hal});
    return out;
}

KinsFiles readKinsFiles(const MachineModel& m, const std::vector<OutputFile>& files, DeviationSet& values) {
    KinsFiles f;
    const IniFragment ini = parseIni(requireFile(files, kKinsIniFile, "LinuxCNC").content, kKinsIniFile);
    f.module = ini.kinematics;
    f.coordinates = ini.trajCoordinates;
    f.joints = ini.joints;
    if (f.coordinates != coordinatesOf(m) || f.joints != m.axisCount())
        throw InputError(kKinsIniFile, 0, fmt::format("JOINTS = {} and COORDINATES = {} do not match machine '{}' ({} joints {})",
                                                      f.joints, f.coordinates, m.name, m.axisCount(), coordinatesOf(m)));
    f.backlash.assign(static_cast<size_t>(m.axisCount()), 0.0);
    for (const auto& [n, b] : ini.backlash) {
        if (n >= m.axisCount()) throw InputError(kKinsIniFile, 0, fmt::format("[JOINT_{}] BACKLASH but only {} joints", n, m.axisCount()));
        f.backlash[static_cast<size_t>(n)] = b * (m.axisLink(n).kind == AxisKind::Rotary ? kDeg : 1.0);
    }
    std::map<std::string, std::pair<int, bool>> pins;  // pin → flat index, set
    for (const DeviationDef& def : m.deviations)
        for (int k = 0; k < def.size(); ++k) pins[pinOf(def, k)] = {def.offset + k, false};
    values = DeviationSet(m);
    for (const TextLine& l : splitLines(requireFile(files, kKinsHalFile, "LinuxCNC").content)) {
        const auto tok = tokens(l.text);
        if (tok.empty() || tok[0].front() == '#') continue;
        if (tok[0] == "net") {
            if (tok.size() == 5 && tok[2] == "motion.tooloffset.z" && tok[3] == "=>" && tok[4] == f.module + ".tool-offset")
                f.toolOffsetNet = true;
            continue;
        }
        if (tok[0] != "setp" || tok.size() != 3) throw InputError(kKinsHalFile, l.number, "expected 'setp <pin> <value>' or 'net'");
        const std::string pin(tok[1]);
        if (!pin.starts_with(f.module + "."))
            throw InputError(kKinsHalFile, l.number, fmt::format("pin '{}' is not a pin of {}", pin, f.module));
        const auto it = pins.find(pin.substr(f.module.size() + 1));
        if (it == pins.end()) throw InputError(kKinsHalFile, l.number, fmt::format("'{}' is no deviation pin of machine '{}'", pin, m.name));
        if (it->second.second) throw InputError(kKinsHalFile, l.number, fmt::format("pin '{}' is set twice", pin));
        values.values[it->second.first] = requireNumber(tok[2], kKinsHalFile, l.number, "the pin value");
        it->second.second = true;
    }
    for (const auto& [pin, where] : pins)
        if (!where.second) throw InputError(kKinsHalFile, 0, fmt::format("pin {}.{} is not set", f.module, pin));
    for (size_t k = 0; k < m.deviations.size(); ++k) {
        const DeviationDef& def = m.deviations[k];
        values.present[k] = values.values.segment(def.offset, def.size()).cwiseAbs().maxCoeff() > 0;
    }
    if (!f.toolOffsetNet)
        throw InputError(kKinsHalFile, 0, fmt::format("no 'net ... motion.tooloffset.z => {}.tool-offset' line", f.module));
    return f;
}

KinsComponentModel::KinsComponentModel(const MachineModel& m, const std::vector<OutputFile>& files, KinsMode mode)
    : machine_(&m), mode_(mode), values_(m), nominal_(m), actual_(m) {
    files_ = readKinsFiles(m, files, values_);
    actual_ = Kinematics(m, values_);
}

AxisVector KinsComponentModel::joints(const AxisVector& q, double toolOffset) const {
    // Both modes aim at the nominal machine's tool pose at q (tool-tip mode: the tip words are that pose's tip and the
    // rotary words its angles), rotary axes pulled towards the words (kins_component.hpp).
    const Vec3 tip = nominal_.toolPoint(toolOffset);
    return solveToolPose(actual_, toolPose(nominal_, q, tip), tip, q, kinsSolverOptions()).q;
}

JointValues KinsComponentModel::program(const AxisVector& q, double toolLength) const {
    const AxisVector c = machine_->toController(q);
    JointValues p(c.size());
    for (int i = 0; i < c.size(); ++i) p[i] = c[i] / (machine_->axisLink(i).kind == AxisKind::Rotary ? kDeg : 1.0);
    if (mode_ == KinsMode::Joint) return p;
    // The tool tip in the workpiece frame as it lies at machine zero (nominal): R0·tip + t0. The program states it
    // as it is (G54 = 0, G43 with the tool length): LinuxCNC adds the tool length to Z (emccanon.cc) and the
    // component takes it off again (tool-offset pin), as trtfuncs.c does.
    const AxisVector qz = machine_->fromController(AxisVector::Zero(c.size()));
    const Pose w0 = nominal_.baseToWorkpiece(qz), t0 = nominal_.baseToTool(qz);
    const Vec3 world = w0.linear() * nominal_.toolPointInWorkpiece(q, nominal_.toolPoint(toolLength)) + w0.translation() - t0.translation();
    for (int k = 0; k < 3; ++k) p[machine_->requireAxis(std::string(1, "XYZ"[k]))] = world[k];
    return p;
}

AxisVector KinsComponentModel::driveCommandsForTool(const AxisVector& q, double toolLength) const {
    // Both modes: the tool-offset pin carries the program's tool length (joint mode: `cnccomp testprog`'s G43.1 Z<L>
    // with the Z words written minus L, postproc/testprog/program_syntax.hpp).
    return joints(q, toolLength);
}

AxisVector KinsComponentModel::driveCommandsMoving(const AxisVector& q, double toolLength, const AxisVector& motion) const {
    AxisVector j = joints(q, toolLength);
    for (int a = 0; a < j.size() && a < motion.size(); ++a)
        j[a] += 0.5 * files_.backlash[static_cast<size_t>(a)] * (motion[a] > 0 ? 1.0 : motion[a] < 0 ? -1.0 : 0.0);
    return j;
}

}  // namespace cnccomp::controllers::linuxcnc
