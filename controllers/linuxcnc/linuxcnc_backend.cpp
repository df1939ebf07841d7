// LinuxCNC backends (LinuxCNC 2.9). The pins-and-tables route ("linuxcnc-pins", for users who cannot compile a
// module): joint compensation tables (COMP_FILE_TYPE 1), INI and HAL fragments for the trt kinematics pins (absolute,
// LinuxCNC's frame), the G54 of the workpiece origin, a README.txt that says how to merge them; and the apply model
// (linuxcnc_apply.hpp) that reads them back and moves like LinuxCNC. Its values are fitted over the request's
// workspace (controllers/common/fit.hpp) when one is given.
#include <algorithm>
#include <cmath>
#include <optional>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "controllers/common/controller_model.hpp"
#include "controllers/common/files.hpp"
#include "controllers/common/fit.hpp"
#include "controllers/common/header.hpp"
#include "controllers/linuxcnc/comp_table.hpp"
#include "controllers/linuxcnc/component_route.hpp"
#include "controllers/linuxcnc/config_files.hpp"
#include "controllers/linuxcnc/laser_comp.hpp"
#include "controllers/linuxcnc/linuxcnc_apply.hpp"
#include "controllers/linuxcnc/linuxcnc_plan.hpp"

namespace cnccomp::controllers::linuxcnc {
using namespace cnccomp::controllers::common;
namespace {

std::string compFileName(const JointPlan& j) { return j.name + ".comp"; }
std::string unitName(bool rotary) { return rotary ? "deg" : "mm"; }

/// One joint's table: points over the travel, trims in LinuxCNC units, and the largest gap between the table's
/// linear interpolation and the exact trim (checked at 8 points inside every interval).
struct JointTable {
    CompTable table;
    double interpolationError = 0;  ///< mm or deg
};

JointTable jointTable(const MachineModel& m, const DeviationSet& d, const JointPlan& j) {
    JointTable out;
    const double unit = j.rotary ? kDeg : 1.0, limit = 5.0 * unit;
    const std::vector<double> nodes = tableNodes(m, j);
    for (double p : nodes) {
        const double trim = jointTrim(m, d, j, p);
        if (!std::isfinite(trim) || std::abs(trim) > limit)
            throw ModelError(fmt::format("joint {}: trim {:.4f} at {:.4f} exceeds the ±5 {} sanity limit (check the deviation units)",
                                         j.name, trim / unit, p / unit, unitName(j.rotary)));
        out.table.nominal.push_back((p - j.machineZero) / unit);
        out.table.forward.push_back(trim / unit);
        out.table.reverse.push_back(trim / unit);
    }
    for (size_t i = 0; i + 1 < nodes.size(); ++i)
        for (int k = 1; k < 8; ++k) {
            const double p = nodes[i] + (nodes[i + 1] - nodes[i]) * k / 8.0;
            const double table = out.table.trim((p - j.machineZero) / unit) * unit;
            out.interpolationError = std::max(out.interpolationError, std::abs(table - jointTrim(m, d, j, p)) / unit);
        }
    return out;
}

std::string pinLine(const std::string& module, const char* pin, double nominal, double value) {
    return fmt::format("# {:<12} nominal {:>14}  delta {:>10}  new {:>14}\n", pin, fixed(nominal, 6), fixed(value - nominal, 6),
                       fixed(value, 6)) +
           fmt::format("setp {}.{} {}\n", module, pin, fixed(value, 6));
}

std::string readme(const LinuxcncPlan& plan, const std::string& module, const std::vector<OutputFile>& tables) {
    std::string r = "\nFiles\n";
    for (const OutputFile& f : tables)
        r += fmt::format("  {:<16} joint table: nominal joint position, forward trim, reverse trim (COMP_FILE_TYPE 1)\n", f.name);
    r += fmt::format("  {:<16} INI fragment: [KINS] and the [JOINT_n] COMP_FILE lines\n", kIniFile);
    if (plan.trt) {
        r += fmt::format("  {:<16} HAL fragment: absolute values of the {} pins, tool-offset net\n", kHalFile, module);
        r += fmt::format("  {:<16} G54 of the machine description's workpiece origin (absolute)\n", kWorkOffsetFile);
    } else {
        r += fmt::format("  {:<16} HAL fragment (trivkins: nothing to set)\n", kHalFile);
    }
    r += "\nFor LinuxCNC 2.9 (checked in cnccomp's tests against the real LinuxCNC 2.9 of Debian 12, linuxcnc-uspace).\n";
    if (plan.trt && *plan.trt == TrtType::BC)
        r += "Do NOT load on LinuxCNC 2.10/master: its xyzbc-trt-kins inverse (conventional-directions = 0) uses the opposite\n"
             "sign of sin(B) in its x-offset / z-offset + tool-offset terms, so the joints differ from 2.9's by up to\n"
             "2*|sin B|*|z-offset + tool length| in X and 2*|sin B|*|x-offset| in Z.\n";
    r += "\nHow to merge\n"
         "1. Tables: copy the .comp files into the folder of your machine INI (COMP_FILE names are relative to it).\n"
         "   They hold no comment lines: LinuxCNC stops reading a table at the first line that is not three numbers.\n"
         "   Nominals are joint positions (machine coordinates, from machine zero; mm, deg); the trims are deltas added\n"
         "   to the joint command. A table covers the joint's whole travel of the machine description: LinuxCNC looks it\n"
         "   up at the raw joint position (no modulo, also with WRAPPED_ROTARY = 1) and holds the end values beyond it.\n"
         "   A joint takes its trim while it moves (forward column moving +, reverse moving -) and keeps it while it\n"
         "   stands; after homing the trim is 0 until the joint's first move (control.c compute_screw_comp).\n"
         "2. INI: copy every KEY = value of cnccomp.ini into the section of the same name of your machine INI, replacing\n"
         "   the key where it is already there; keep everything else (limits, homing, scales).\n"
         "   BACKLASH: LinuxCNC does not apply [JOINT_n] BACKLASH to a joint with a COMP_FILE (ini-config.adoc).\n"
         "   A table carries the deviation set's reversal value B<axis> (ISO 230-2 mean reversal) in its columns:\n"
         "   forward trim - reverse trim = -B; without B<axis> forward = reverse. A joint without a table gets\n"
         "   BACKLASH = -B<axis> in cnccomp.ini. If a joint with a table and no B<axis> has BACKLASH = b today,\n"
         "   add +b/2 to every forward trim and -b/2 to every reverse trim of its table, or that backlash compensation is lost.\n";
    if (plan.trt) {
        r += fmt::format(
            "3. HAL: cnccomp.hal holds ABSOLUTE values in LinuxCNC's frame (mm; the joints are the tool control point at\n"
            "   tool length 0, measured from machine zero). They REPLACE your values of exactly these pins of {}:\n"
            "     {}\n"
            "   Delete or overwrite your own setp lines of these pins (or load cnccomp.hal as a HALFILE after yours:\n"
            "   a later setp wins); a pin driven by a signal (net ... with sets) takes the new value through its\n"
            "   signal: sets <signal> <value> instead of the setp line.\n"
            "   Before replacing: your current values must equal the 'nominal' ones listed in cnccomp.hal (the machine\n"
            "   description's geometry in LinuxCNC's frame). If they do not, the description does not describe this\n"
            "   machine as LinuxCNC sees it (offsets, machine-zero): fix it and emit again, or add the listed deltas to\n"
            "   your own values instead of replacing them.\n"
            "   The tool-offset pin must carry the active tool length: keep your own net of motion.tooloffset.z to it,\n"
            "   or the net line of cnccomp.hal, never both.\n"
            "4. G54: cnccomp-g54.ngc sets G54 to the workpiece origin of the machine description (the table frame at\n"
            "   {} = C = 0) as identified, for programs written for that origin. If you touch off or probe the part at\n"
            "   {} = C = 0 as usual, your probing already sees the true table: do not run it.\n",
            module, *plan.trt == TrtType::AC ? "x-rot-point y-rot-point z-rot-point y-offset z-offset" : "x-rot-point y-rot-point z-rot-point x-offset z-offset",
            *plan.trt == TrtType::AC ? "A" : "B", *plan.trt == TrtType::AC ? "A" : "B");
    } else {
        r += "3. HAL: nothing to merge (trivkins has no geometry pins).\n";
    }
    return r;
}

/// The pins-and-tables route's files for the values of the request (no fit here).
EmitResult emitPinsRoute(const EmitRequest& r) {
    const MachineModel& m = r.machine;
    const LinuxcncPlan plan = planLinuxcnc(m, r.deviations);
    EmitResult out;
    out.compensated = plan.compensated;
    out.notCompensated = plan.notCompensated;
    const std::string module = plan.trt ? trtModule(*plan.trt) : "trivkins";

    // Tables first: their coverage goes into every header.
    std::vector<OutputFile> tables;
    std::vector<std::string> tableNotes;
    std::string iniJoints;
    for (size_t n = 0; n < plan.joints.size(); ++n) {
        const JointPlan& j = plan.joints[n];
        // The reversal value B̄ (DeviationSet::reversal, mm, the joint's own direction): alone, BACKLASH = −B̄
        // (laser_comp.hpp); with a table (LinuxCNC ignores BACKLASH then), the table's columns carry it as the laser
        // route's do (forward trim −x̄↑ = −x̄ − B̄/2, reverse trim −x̄↓ = −x̄ + B̄/2).
        const bool hasReversal = !j.rotary && r.deviations.reversalPresent[static_cast<size_t>(j.axis)];
        const double reversal = hasReversal ? r.deviations.reversal[static_cast<size_t>(j.axis)] : 0.0;
        const std::string reversalName = "B" + j.name;
        if (!j.hasTable()) {
            if (hasReversal) {
                const double b = backlashFromReversal(reversal);
                iniJoints += fmt::format("\n[JOINT_{}]\n# axis {}: BACKLASH = -{} (the reversal value of the deviation set){}\n"
                                         "BACKLASH = {}\n",
                                         n, j.name, reversalName,
                                         b < 0 ? kNegativeBacklashNote : "",
                                         fixed(b, 6));
                out.compensated.push_back({reversalName, fmt::format("[JOINT_{}] BACKLASH = {} mm", n, fixed(b, 6))});
            }
            continue;
        }
        JointTable t = jointTable(m, r.deviations, j);
        if (hasReversal) {
            for (size_t i = 0; i < t.table.nominal.size(); ++i) {
                t.table.forward[i] -= 0.5 * reversal;
                t.table.reverse[i] += 0.5 * reversal;
            }
            out.compensated.push_back({reversalName, fmt::format("{}: forward trims {} mm, reverse trims {} mm (the reversal "
                                                                 "value in the columns; BACKLASH does not act with a COMP_FILE)",
                                                                 compFileName(j), fixed(-0.5 * reversal, 6), fixed(0.5 * reversal, 6))});
        }
        const std::string unit = unitName(j.rotary);
        tableNotes.push_back(fmt::format("{}: {} points, joint {} .. {} {} (the whole travel); largest interpolation error {:.2e} {}",
                                         compFileName(j), t.table.nominal.size(), fixed(t.table.nominal.front(), 3),
                                         fixed(t.table.nominal.back(), 3), unit, t.interpolationError, unit));
        tables.push_back({compFileName(j), formatCompTable(t.table, compFileName(j))});
        iniJoints += fmt::format("\n[JOINT_{}]\n# axis {}: LinuxCNC does not apply BACKLASH to this joint while COMP_FILE is set "
                                 "(README-pins.txt)\nCOMP_FILE = {}\nCOMP_FILE_TYPE = 1\n",
                                 n, j.name, compFileName(j));
    }

    std::vector<std::string> notes{
        "route: pins and tables (no module to compile; holds only what joint tables and the trt kinematics pins can "
        "take, see NOT compensated)",
        "for LinuxCNC 2.9 (trtfuncs.c, control.c, usrmotintf.cc of 2.9); checked against the real LinuxCNC 2.9 "
        "(Debian 12 linuxcnc-uspace)",
        fmt::format("kinematics: {} coordinates={} (joint n = letter n)", module, plan.coordinates),
        "tables: COMP_FILE_TYPE 1, nominal = joint position (from machine zero), trims (deltas) added to the joint command"};
    if (plan.trt && *plan.trt == TrtType::BC)
        notes.push_back("NOT for LinuxCNC 2.10/master: its xyzbc-trt-kins inverse differs from 2.9's in the sign of the "
                        "sin(B) offset terms (README-pins.txt)");
    if (!tables.empty() && !r.deviations.hasReversal())
        notes.push_back("WARNING: LinuxCNC ignores BACKLASH for a joint with COMP_FILE; forward = reverse here (no reversal "
                        "error in the deviation set): put the joint's backlash into the columns (README-pins.txt)");
    else if (!tables.empty())
        notes.push_back("LinuxCNC ignores BACKLASH for a joint with COMP_FILE: a joint with a table carries the deviation set's "
                        "reversal value in its columns (forward - reverse = -B), the others get BACKLASH = -B (README-pins.txt)");
    notes.insert(notes.end(), tableNotes.begin(), tableNotes.end());
    if (plan.trt) {
        const TrtPins &p = plan.pins, &n = plan.nominalPins;
        const bool ac = *plan.trt == TrtType::AC;
        notes.push_back(fmt::format("pins: ABSOLUTE, LinuxCNC's frame (mm from machine zero, joints = tool control point); "
                                    "nominal x/y/z-rot-point {} {} {}, {} {}, z-offset {}; new {} {} {}, {} {}, z-offset {}",
                                    fixed(n.xRotPoint, 6), fixed(n.yRotPoint, 6), fixed(n.zRotPoint, 6), ac ? "y-offset" : "x-offset",
                                    fixed(ac ? n.yOffset : n.xOffset, 6), fixed(n.zOffset, 6), fixed(p.xRotPoint, 6),
                                    fixed(p.yRotPoint, 6), fixed(p.zRotPoint, 6), ac ? "y-offset" : "x-offset",
                                    fixed(ac ? p.yOffset : p.xOffset, 6), fixed(p.zOffset, 6)));
        notes.push_back(fmt::format("G54 of the workpiece origin: ABSOLUTE, nominal X {} Y {} Z {}, new X {} Y {} Z {} mm",
                                    fixed(plan.nominalWorkOffset.x(), 6), fixed(plan.nominalWorkOffset.y(), 6),
                                    fixed(plan.nominalWorkOffset.z(), 6), fixed(plan.workOffset.x(), 6),
                                    fixed(plan.workOffset.y(), 6), fixed(plan.workOffset.z(), 6)));
        notes.push_back(fmt::format("tool-offset: motion.tooloffset.z => {}.tool-offset (the TCP needs the active tool length)", module));
        notes.push_back(fmt::format("kinematics modes: the pins act in tool-tip mode only ({} switchkins-type 0, tool tip in "
                                    "workpiece coordinates); joint-mode programs (identity kinematics, switchkins-type 1, e.g. "
                                    "cnccomp testprog's) get the joint tables only",
                                    module));
    }
    const HeaderInfo h = makeHeaderInfo(r, fmt::format("LinuxCNC 2.9 ({})", module), out, notes);

    out.files = tables;
    std::string ini = formatHeader(h, "# ");
    ini += fmt::format("\n[KINS]\nKINEMATICS = {} coordinates={}\nJOINTS = {}\n", module, plan.coordinates, plan.joints.size());
    ini += iniJoints;
    out.files.push_back({kIniFile, ini});
    std::string hal = formatHeader(h, "# ");
    if (plan.trt) {
        const TrtPins &p = plan.pins, &n = plan.nominalPins;
        hal += fmt::format("\n# Absolute values in LinuxCNC's frame; they replace these pins' values (README-pins.txt).\n"
                           "net tooloffset-z motion.tooloffset.z => {}.tool-offset\n",
                           module);
        hal += pinLine(module, "x-rot-point", n.xRotPoint, p.xRotPoint);
        hal += pinLine(module, "y-rot-point", n.yRotPoint, p.yRotPoint);
        hal += pinLine(module, "z-rot-point", n.zRotPoint, p.zRotPoint);
        if (*plan.trt == TrtType::AC) hal += pinLine(module, "y-offset", n.yOffset, p.yOffset);
        else hal += pinLine(module, "x-offset", n.xOffset, p.xOffset);
        hal += pinLine(module, "z-offset", n.zOffset, p.zOffset);
        // LinuxCNC aborts a program at a line of 254 characters or more ("Command too long").
        std::string g54 = wrapCommentLines(formatHeader(h, "; "), "; ");
        g54 += fmt::format("\n; G54 = the workpiece origin of the machine description in LinuxCNC's frame, absolute (README-pins.txt)\n"
                           "G10 L2 P1 X{} Y{} Z{}\nM2\n",
                           fixed(plan.workOffset.x(), 6), fixed(plan.workOffset.y(), 6), fixed(plan.workOffset.z(), 6));
        out.files.push_back({kHalFile, hal});
        out.files.push_back({kWorkOffsetFile, g54});
    } else {
        hal += "\n# trivkins: no kinematics pins to set\n";
        out.files.push_back({kHalFile, hal});
    }
    out.files.push_back({kReadmeFile, formatHeader(h, "") + readme(plan, module, tables)});
    return out;
}

/// The pins route's files of a folder (which may hold the component route too).
std::vector<OutputFile> pinsFiles(const std::vector<OutputFile>& files) {
    std::vector<OutputFile> out;
    for (const OutputFile& f : files)
        if (f.name == kIniFile || f.name == kHalFile || f.name == kWorkOffsetFile || f.name == kReadmeFile ||
            (f.name.ends_with(".comp") && f.name != kKinsSourceFile))
            out.push_back(f);
    return out;
}

/// The pins route with the trt pins acting (tool-tip mode): what its values are fitted through. Not registered.
class PinsToolTipFit final : public Backend {
public:
    std::string_view name() const override { return "linuxcnc-pins"; }
    std::string_view description() const override { return "LinuxCNC pins route, tool-tip mode (fit only)"; }
    EmitResult emit(const EmitRequest& r) const override { return emitPinsRoute(r); }
    std::unique_ptr<AppliedCompensation> apply(const MachineModel& m, const std::vector<OutputFile>& files) const override {
        return std::make_unique<LinuxcncModel>(m, files, matchTrt(m) ? KinsMode::ToolTip : KinsMode::Joint);
    }
};

/// The pins route, its values fitted over the request's workspace when there is one (in tool-tip mode: the trt pins
/// only act there; the joint tables act in both modes).
EmitResult emitFittedPinsRoute(const EmitRequest& r) {
    if (!r.fitWorkspace) return emitPinsRoute(r);
    const FitOutcome fit = fitControllerValues(PinsToolTipFit{}, r.machine, r.deviations, *r.fitWorkspace);
    EmitRequest fitted{r.machine, fit.written, r.deviationSource, r.date, r.fitWorkspace, r.headerNotes};
    fitted.headerNotes.insert(fitted.headerNotes.end(), fit.notes.begin(), fit.notes.end());
    return emitPinsRoute(fitted);
}

class LinuxcncPinsBackend final : public Backend {
public:
    std::string_view name() const override { return "linuxcnc-pins"; }
    std::string_view description() const override {
        return "LinuxCNC 2.9, pins-and-tables route (no module to compile): joint COMP_FILE_TYPE 1 tables, INI/HAL fragments "
               "for xyzac/xyzbc-trt-kins pins (absolute, LinuxCNC's frame), G54 program";
    }
    EmitResult emit(const EmitRequest& r) const override { return emitFittedPinsRoute(r); }
    /// Joint mode: the mode of the test programs (linuxcnc_apply.hpp).
    std::unique_ptr<AppliedCompensation> apply(const MachineModel& m, const std::vector<OutputFile>& files) const override {
        return std::make_unique<LinuxcncModel>(m, files, KinsMode::Joint);
    }
    /// A folder of the pins route alone (`emit --controller linuxcnc-pins`); name this backend to verify the pins route
    /// of a folder holding both routes.
    bool recognizes(const std::vector<OutputFile>& files) const override {
        return findFile(files, kIniFile) && !findFile(files, kKinsIniFile);
    }
    std::vector<OutputFile> ownFiles(const std::vector<OutputFile>& files) const override { return pinsFiles(files); }
};

/// README.txt of a folder holding both routes: which files are which route, how to build and load the component.
std::string componentReadme(const EmitRequest& r, const EmitResult& kins, const EmitResult* pins, const std::string& pinsRefused) {
    const MachineModel& m = r.machine;
    std::string coordinates;
    for (const std::string& a : m.axisNames) coordinates += a;
    const HeaderInfo h = makeHeaderInfo(r, fmt::format("LinuxCNC 2.9 (component {}, and the pins-and-tables route)", kKinsName), kins);
    std::string t = formatHeader(h, "");
    t += fmt::format(
        "\nThis folder holds two routes. Load ONE of them.\n"
        "\n"
        "Route 1, generated kinematics component (the whole model; what cnccomp verify and emit's prediction use):\n"
        "  {:<20} the component source (C for halcompile)\n"
        "  {:<20} INI fragment: [KINS] KINEMATICS, JOINTS and [TRAJ] COORDINATES\n"
        "  {:<20} HAL fragment: the tool-offset net and the deviation values (setp lines)\n",
        kKinsSourceFile, kKinsIniFile, kKinsHalFile);
    if (pins) {
        t += "\nRoute 2, pins and tables (for a LinuxCNC where modules cannot be compiled; holds only what joint tables\n"
             "and the xyzac/xyzbc-trt-kins pins can take, see README-pins.txt and the NOT compensated list there):\n";
        for (const OutputFile& f : pins->files) t += fmt::format("  {}\n", f.name);
        t += "  Verify it with cnccomp verify --controller linuxcnc-pins --compensation <this folder>.\n";
    } else {
        t += fmt::format("\nRoute 2, pins and tables: not written for this machine: {}\n", pinsRefused);
    }
    t += fmt::format(
        "\nRoute 1: build and install (once per change of the component; as root for a package install of LinuxCNC)\n"
        "  apt-get install linuxcnc-uspace-dev      (brings halcompile)\n"
        "  halcompile --install {}\n"
        "  It installs {}.so into LinuxCNC's module folder (/usr/lib/linuxcnc/modules for the Debian package).\n"
        "\n"
        "Route 1: load\n"
        "1. INI: put KINEMATICS and JOINTS of {} into [KINS] and COORDINATES into [TRAJ], replacing your keys.\n"
        "   Joint n is machine axis n = letter n of COORDINATES = {} (controller machine coordinates, mm and deg):\n"
        "   order your [JOINT_n] sections and the drives' nets to match. Remove the COMP_FILE lines of the pins route if\n"
        "   you loaded it before: the component already holds the axes' own errors (they would count twice).\n"
        "2. HAL: add {} as a HALFILE after your own. Remove the setp lines and the tool-offset net of your previous\n"
        "   kinematics module (a pin takes one net only). Changing a dev.* pin changes the model at once: set them only\n"
        "   with the machine stopped.\n"
        "3. Modes: switchkins-type 0 (default at start) is joint mode: the axis words are the nominal machine's\n"
        "   commands and the component puts the real tool where the nominal one would be (run cnccomp testprog's\n"
        "   programs this way). The tool tip is kept exact at the tool-offset pin's length (motion.tooloffset.z): where\n"
        "   the tool axis cannot follow (near a singular pose) only that point is. cnccomp testprog's programs give\n"
        "   their tool length with G43.1 Z<L> and write Z minus L; a program whose Z words already hold the tool\n"
        "   length (G49) is exact at length 0. switchkins-type 1 is tool-tip mode: X Y Z = tool tip in the workpiece frame as it\n"
        "   lies at machine zero, rotary words = the angles, with G43 the active tool's length. To switch from a\n"
        "   program: net cnccomp-kinstype motion.analog-out-03 => motion.switchkins-type, then M68 E3 Q1 (or Q0)\n"
        "   followed by M66 E0 L0 (as LinuxCNC's switchkins sample configurations do with M428/M429).\n"
        "4. Check: {}.fail goes true when an inverse does not converge; {}.residual is the tip residual (mm).\n",
        kKinsSourceFile, kKinsName, kKinsIniFile, coordinates, kKinsHalFile, kKinsName, kKinsName);
    return t;
}

/// Both routes: the component route (default) and, when the machine allows, the fitted pins route.
class LinuxcncBackend final : public Backend {
public:
    std::string_view name() const override { return "linuxcnc"; }
    std::string_view description() const override {
        return "LinuxCNC 2.9: a generated kinematics component holding the whole model (route 1, default), and the "
               "pins-and-tables route (route 2: joint COMP_FILE tables, xyzac/xyzbc-trt-kins pins, G54 program)";
    }
    EmitResult emit(const EmitRequest& r) const override {
        EmitResult out = emitComponentRoute(r);
        std::optional<EmitResult> pins;
        std::string refused;
        try {
            pins = emitFittedPinsRoute(r);
        } catch (const ModelError& e) {
            refused = e.what();
        }
        const std::vector<OutputFile> kinsFiles = out.files;
        out.files.push_back({"README.txt", componentReadme(r, out, pins ? &*pins : nullptr, refused)});
        std::string kinsNames, pinsNames;
        for (const OutputFile& f : kinsFiles) kinsNames += " " + f.name;
        out.summary.push_back("route 1, generated kinematics component (the whole model; verify and the prediction use it):" + kinsNames);
        if (pins) {
            for (const OutputFile& f : pins->files) {
                pinsNames += " " + f.name;
                out.files.push_back(f);
            }
            out.summary.push_back("route 2, pins and tables (no module to compile; verify it with --controller linuxcnc-pins):" +
                                  pinsNames);
            for (const Coverage& c : pins->notCompensated)
                out.summary.push_back(fmt::format("  route 2 does not compensate {}: {}", c.deviation, c.note));
        } else {
            out.summary.push_back("route 2, pins and tables: not written: " + refused);
        }
        out.summary.push_back("README.txt: how to build (halcompile --install) and load each route");
        return out;
    }
    /// The component route when its files are there, else the pins route; joint mode (the test programs' mode).
    std::unique_ptr<AppliedCompensation> apply(const MachineModel& m, const std::vector<OutputFile>& files) const override {
        if (findFile(files, kKinsIniFile)) return std::make_unique<KinsComponentModel>(m, files, KinsMode::Joint);
        return std::make_unique<LinuxcncModel>(m, files, KinsMode::Joint);
    }
    bool recognizes(const std::vector<OutputFile>& files) const override { return findFile(files, kKinsIniFile) != nullptr; }
    /// The component route's files and README.txt.
    std::vector<OutputFile> ownFiles(const std::vector<OutputFile>& files) const override {
        if (!findFile(files, kKinsIniFile)) return pinsFiles(files);
        std::vector<OutputFile> out;
        for (const OutputFile& f : files)
            if (f.name == "README.txt" || f.name == kKinsIniFile || f.name == kKinsHalFile || f.name == kKinsSourceFile) out.push_back(f);
        return out;
    }
};

const RegisterBackend reg(std::make_unique<LinuxcncBackend>());
const RegisterBackend regPins(std::make_unique<LinuxcncPinsBackend>());

}  // namespace
}  // namespace cnccomp::controllers::linuxcnc
