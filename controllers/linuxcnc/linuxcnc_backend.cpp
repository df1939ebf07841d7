// LinuxCNC backend: joint compensation tables (COMP_FILE_TYPE 1), INI and HAL fragments for the trt kinematics
// pins, a README.txt; and the apply model that reads them back and moves like LinuxCNC (kinematics inverse with
// the HAL pins, then the joint trims).
#include <algorithm>
#include <cmath>
#include <set>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "controllers/common/controller_model.hpp"
#include "controllers/common/files.hpp"
#include "controllers/common/header.hpp"
#include "controllers/linuxcnc/comp_table.hpp"
#include "controllers/linuxcnc/config_files.hpp"
#include "controllers/linuxcnc/linuxcnc_plan.hpp"

namespace cnccomp::controllers::linuxcnc {
namespace {

constexpr const char* kIni = "cnccomp.ini";
constexpr const char* kHal = "cnccomp.hal";
constexpr const char* kReadme = "README.txt";

double unitScale(bool rotary) { return rotary ? 1.0 / kDeg : 1.0; }

/// Table nodes (internal units) of a joint: exact breakpoints of table-type component errors when they fit,
/// otherwise 256 equidistant points; a modulo joint gets [0°, 360°] and closes on itself.
std::vector<double> tableNodes(const MachineModel& m, const JointPlan& j) {
    bool allTables = true;
    std::set<double> nodes;
    const Link& l = m.axisLink(j.axis);
    for (const OwnComponent& c : j.components) {
        const ComponentBasis& b = m.deviations[c.deviation].basis;
        if (b.type != ComponentBasis::Type::Table) allTables = false;
        for (double n : b.nodes) nodes.insert(n);
    }
    std::vector<double> out;
    if (j.modulo) {
        const double period = 2 * kPi;
        std::set<double> wrapped{0.0, period};
        for (double n : nodes) {
            double u = std::fmod(n, period);
            if (u < 0) u += period;
            wrapped.insert(u);
        }
        if (!j.components.empty() && (!allTables || wrapped.size() > static_cast<size_t>(kMaxCompLines))) {
            wrapped.clear();
            for (int i = 0; i <= 240; ++i) wrapped.insert(i * 1.5 * kDeg);  // 1.5° divides 360°
        }
        for (double u : wrapped)
            if (out.empty() || u - out.back() > 1e-12) out.push_back(u);
        return out;
    }
    if (!std::isfinite(l.min) || !std::isfinite(l.max) || !(l.max > l.min))
        throw ModelError(fmt::format("axis {} has no finite travel: a LinuxCNC table needs one", l.name));
    std::set<double> s{l.min, l.max};
    for (double n : nodes)
        if (n > l.min && n < l.max) s.insert(n);
    if (!j.components.empty() && (!allTables || s.size() > static_cast<size_t>(kMaxCompLines))) {
        s.clear();
        for (int i = 0; i < kMaxCompLines; ++i) s.insert(l.min + (l.max - l.min) * i / (kMaxCompLines - 1));
    }
    for (double u : s)
        if (out.empty() || u - out.back() > 1e-12) out.push_back(u);
    return out;
}

std::string compFileName(const JointPlan& j) { return j.name + ".comp"; }

class LinuxcncApplied final : public AppliedCompensation {
public:
    const MachineModel* machine = nullptr;
    std::vector<int> jointAxis;
    std::optional<TrtType> trt;
    TrtPins nominal, pins;
    std::array<double, 3> shift{};
    std::vector<std::optional<CompTable>> tables;
    std::vector<char> wrap;
    int jx = -1, jy = -1, jz = -1, jt = -1, jc = -1;  // joint numbers of the trt letters

    AxisVector driveCommands(const AxisVector& q) const override {
        const int n = static_cast<int>(jointAxis.size());
        std::array<double, kMaxAxes> J{};
        for (int i = 0; i < n; ++i) J[i] = q[jointAxis[i]] * unitScale(machine->axisLink(jointAxis[i]).kind == AxisKind::Rotary);
        if (trt) {
            // The program (nominal machine, work offsets referring to the table centre) → world coordinates of the
            // module, shifted by the work-offset change README.txt asks for, → joints with the corrected pins.
            TrtPose j{{J[jx], J[jy], J[jz]}, J[jt], J[jc]};
            TrtPose w = trtForward(*trt, nominal, j);
            for (int k = 0; k < 3; ++k) w.xyz[k] += shift[k];
            const TrtPose jj = trtInverse(*trt, pins, w);
            J[jx] = jj.xyz[0];
            J[jy] = jj.xyz[1];
            J[jz] = jj.xyz[2];
        }
        for (int i = 0; i < n; ++i) {
            if (!tables[i]) continue;
            double p = J[i];
            if (wrap[i]) {
                p = std::fmod(p, 360.0);
                if (p < 0) p += 360.0;
            }
            J[i] += tables[i]->trim(p);
        }
        AxisVector out = q;
        for (int i = 0; i < n; ++i)
            out[jointAxis[i]] = J[i] / unitScale(machine->axisLink(jointAxis[i]).kind == AxisKind::Rotary);
        return out;
    }
};

class LinuxcncBackend final : public Backend {
public:
    std::string_view name() const override { return "linuxcnc"; }
    std::string_view description() const override {
        return "LinuxCNC 2.9: joint COMP_FILE_TYPE 1 tables, INI/HAL fragments for xyzac/xyzbc-trt-kins pins";
    }

    EmitResult emit(const EmitRequest& r) const override {
        const MachineModel& m = r.machine;
        const LinuxcncPlan plan = planLinuxcnc(m, r.deviations);
        EmitResult out;
        out.compensated = plan.compensated;
        out.notCompensated = plan.notCompensated;
        const std::string module = plan.trt ? trtModule(*plan.trt) : "trivkins";
        std::vector<std::string> notes{
            fmt::format("kinematics: {} coordinates={} (joint n = letter n)", module, plan.coordinates),
            "tables: COMP_FILE_TYPE 1, trims added to the joint command, forward = reverse (no reversal error given)"};
        bool wrapped = false;
        for (const JointPlan& j : plan.joints) wrapped |= j.modulo && j.hasTable();
        if (wrapped)
            notes.push_back("[G] modulo tables span 0..360 deg and assume WRAPPED_ROTARY = 1 keeps the joint position in 0..360");
        if (plan.trt) {
            notes.push_back(fmt::format("pins in the machine model's frame (origin at the nominal {} / C intersection); nominal "
                                        "x/y/z-rot-point {} {} {} mm",
                                        *plan.trt == TrtType::AC ? "A" : "B", fixed(plan.nominalPins.xRotPoint, 6),
                                        fixed(plan.nominalPins.yRotPoint, 6), fixed(plan.nominalPins.zRotPoint, 6)));
            notes.push_back(fmt::format("work offsets that refer to the table centre move by X {} Y {} Z {} mm (e.g. G10 L2 P1 adds them)",
                                        fixed(plan.workOffsetShift[0], 6), fixed(plan.workOffsetShift[1], 6),
                                        fixed(plan.workOffsetShift[2], 6)));
            notes.push_back(fmt::format("[G] the tool-offset pin is expected to be driven by motion.tooloffset.z (net in the HAL file)"));
        }
        const HeaderInfo h = makeHeaderInfo(r, fmt::format("LinuxCNC ({})", module), out, notes);

        // Tables.
        std::string iniJoints;
        for (size_t n = 0; n < plan.joints.size(); ++n) {
            const JointPlan& j = plan.joints[n];
            if (!j.hasTable()) continue;
            CompTable t;
            const double s = unitScale(j.rotary);
            for (double p : tableNodes(m, j)) {
                const double trim = jointTrim(m, r.deviations, j, p);
                const double limit = j.rotary ? 5.0 * kDeg : 5.0;
                if (!std::isfinite(trim) || std::abs(trim) > limit)
                    throw ModelError(fmt::format("joint {}: trim {:.4f} at {:.4f} exceeds the ±5 {} sanity limit (check the deviation units)",
                                                 j.name, trim * s, p * s, j.rotary ? "deg" : "mm"));
                t.nominal.push_back(p * s);
                t.forward.push_back(trim * s);
                t.reverse.push_back(trim * s);
            }
            if (j.modulo) t.forward.back() = t.reverse.back() = t.forward.front();  // closes on itself
            out.files.push_back({compFileName(j), formatCompTable(t, compFileName(j))});
            iniJoints += fmt::format("\n[JOINT_{}]\n# axis {}\nCOMP_FILE = {}\nCOMP_FILE_TYPE = 1\n", n, j.name, compFileName(j));
            if (j.modulo) iniJoints += fmt::format("\n[AXIS_{}]\n# [G] keeps the joint in 0..360 so that the table applies every turn\nWRAPPED_ROTARY = 1\n", j.name);
        }
        std::string ini = formatHeader(h, "# ");
        ini += fmt::format("\n[KINS]\nKINEMATICS = {} coordinates={}\nJOINTS = {}\n", module, plan.coordinates, plan.joints.size());
        ini += iniJoints;
        std::string hal = formatHeader(h, "# ");
        if (plan.trt) {
            const TrtPins& p = plan.pins;
            hal += fmt::format("\nnet tooloffset-z motion.tooloffset.z => {}.tool-offset\n", module);
            hal += fmt::format("setp {}.x-rot-point {}\nsetp {}.y-rot-point {}\nsetp {}.z-rot-point {}\n", module, fixed(p.xRotPoint, 6),
                               module, fixed(p.yRotPoint, 6), module, fixed(p.zRotPoint, 6));
            if (*plan.trt == TrtType::AC) hal += fmt::format("setp {}.y-offset {}\n", module, fixed(p.yOffset, 6));
            else hal += fmt::format("setp {}.x-offset {}\n", module, fixed(p.xOffset, 6));
            hal += fmt::format("setp {}.z-offset {}\n", module, fixed(p.zOffset, 6));
        } else {
            hal += "\n# trivkins: no kinematics pins to set\n";
        }
        std::string readme = formatHeader(h, "");
        readme += "\nFiles\n";
        for (const OutputFile& f : out.files) readme += fmt::format("  {:<12} joint compensation table (nominal forward-trim reverse-trim)\n", f.name);
        readme += fmt::format("  {:<12} INI fragment: merge [KINS] and the [JOINT_n] COMP_FILE lines into the machine INI\n", kIni);
        readme += fmt::format("  {:<12} HAL fragment: add to a HAL file loaded after the kinematics module\n", kHal);
        readme += "\nThe .comp files hold no comment lines: LinuxCNC stops reading a table at the first line that is not\n"
                  "three numbers. Units: mm for linear joints, degrees for rotary joints.\n";
        out.files.push_back({kIni, ini});
        out.files.push_back({kHal, hal});
        out.files.push_back({kReadme, readme});
        return out;
    }

    std::unique_ptr<AppliedCompensation> apply(const MachineModel& m, const std::vector<OutputFile>& files) const override {
        const IniFragment ini = parseIni(requireFile(files, kIni, "LinuxCNC").content, kIni);
        auto a = std::make_unique<LinuxcncApplied>();
        a->machine = &m;
        if (static_cast<int>(ini.coordinates.size()) != m.axisCount())
            throw InputError(kIni, 0, fmt::format("coordinates={} do not match the {} axes of machine '{}'", ini.coordinates,
                                                  m.axisCount(), m.name));
        for (char c : ini.coordinates) {
            const int axis = m.axisIndex(std::string(1, c));
            if (axis < 0) throw InputError(kIni, 0, fmt::format("machine '{}' has no axis {}", m.name, c));
            a->jointAxis.push_back(axis);
        }
        if (ini.kinematics != "trivkins") {
            const auto type = matchTrt(m);
            if (!type || trtModule(*type) != ini.kinematics)
                throw InputError(kIni, 0, fmt::format("kinematics {} does not fit machine '{}'", ini.kinematics, m.name));
            a->trt = type;
            const auto pins = parseHal(requireFile(files, kHal, "LinuxCNC").content, kHal, ini.kinematics);
            if (!pins) throw InputError(kHal, 0, fmt::format("no {} pin is set", ini.kinematics));
            a->pins = *pins;
            a->nominal = trtPins(m, *type, nullptr);
            a->pins.toolOffset = a->nominal.toolOffset = 0.0;  // both sides see the same tool offset
            a->shift = {a->pins.xRotPoint - a->nominal.xRotPoint, a->pins.yRotPoint - a->nominal.yRotPoint,
                        a->pins.zRotPoint - a->nominal.zRotPoint};
            const auto jointOf = [&](char c) { return static_cast<int>(ini.coordinates.find(c)); };
            a->jx = jointOf('X');
            a->jy = jointOf('Y');
            a->jz = jointOf('Z');
            a->jt = jointOf(*type == TrtType::AC ? 'A' : 'B');
            a->jc = jointOf('C');
        }
        a->tables.resize(ini.coordinates.size());
        a->wrap.assign(ini.coordinates.size(), 0);
        for (const auto& [n, file] : ini.compFile) {
            if (n >= static_cast<int>(ini.coordinates.size()))
                throw InputError(kIni, 0, fmt::format("[JOINT_{}] but only {} joints", n, ini.coordinates.size()));
            a->tables[n] = parseCompTable(requireFile(files, file, "LinuxCNC").content, file);
            const auto w = ini.wrapped.find(ini.coordinates[n]);
            a->wrap[n] = w != ini.wrapped.end() && w->second;
        }
        return a;
    }
};

const RegisterBackend reg(std::make_unique<LinuxcncBackend>());

}  // namespace
}  // namespace cnccomp::controllers::linuxcnc
