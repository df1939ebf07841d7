// cnccomp laser: the ISO 230-2 evaluation of a laser interferometer's bidirectional positioning runs of one linear
// axis (io/laser_csv.hpp for the file layout), printed as a table, optionally as JSON and as a LinuxCNC pitch-error
// table (controllers/linuxcnc/laser_comp.hpp for its sign and INI lines), and with --machine as the axis' positioning
// component error in a deviation set (cnccomp/laser_deviation.hpp), merged into an existing set with --merge. All files
// are written together or not at all.
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "cli/command.hpp"
#include "cnccomp/error.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/laser_csv.hpp"
#include "cnccomp/io/laser_report.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "cnccomp/io/output_set.hpp"
#include "cnccomp/laser_deviation.hpp"
#include "cnccomp/laser_positioning.hpp"
#include "controllers/fanuc/laser_pitch.hpp"
#include "controllers/heidenhain/laser_com.hpp"
#include "controllers/isg/laser_lsec.hpp"
#include "controllers/linuxcnc/laser_comp.hpp"
#include "controllers/siemens/laser_eec.hpp"

namespace cnccomp::cli {
using namespace cnccomp::io;
namespace {

struct Options {
    std::string file, json, compOut, machine, deviationsOut, merge, controller = "linuxcnc", referenceDirection = "+";
    int joint = -1, axisNumber = 0;
    LaserCsvOptions csv;
};

void run(const Options& o) {
    const bool linuxcnc = o.controller == "linuxcnc";
    if (!o.compOut.empty() && linuxcnc && o.joint < 0)
        throw InputError("", 0, "--comp-out needs --joint N (the [JOINT_N] section the table belongs to)");
    if (!o.compOut.empty() && (o.controller == "fanuc-30i" || o.controller == "siemens-840d" || o.controller == "isg") &&
        o.axisNumber < 1)
        throw InputError("", 0, fmt::format("--controller {} needs --axis-number N (the control's number of the axis)", o.controller));
    const bool referenceForward = o.referenceDirection == "+";
    if (!o.deviationsOut.empty() && o.machine.empty())
        throw InputError("", 0, "--deviations-out needs --machine M.xml (the machine whose positioning component it sets)");
    if (!o.merge.empty() && o.deviationsOut.empty()) throw InputError("", 0, "--merge needs --deviations-out");
    const LaserCsvFile in = readLaserCsv(o.file, o.csv);
    const LaserPositioningResult r = evaluateLaserPositioning(in.runs);
    fmt::print("{}", formatLaserTable(r, in.environmentStated));

    OutputSet out({o.file, o.machine, o.merge});
    std::string deviationNote;
    if (!o.deviationsOut.empty()) {
        const MachineModel m = readMachineXml(o.machine);
        DeviationSet laser(m);
        const LaserComponentResult c = setPositioningComponent(laser, r, o.file);
        std::string mergeLines;
        DeviationSet set = laser;
        if (!o.merge.empty()) {
            const DeviationSet base = readDeviationCsv(o.merge, m);
            for (const std::string& l : reversalMergeLines(base, laser, "the laser")) mergeLines += "merge: " + l + "\n";
            set = mergeDeviations(base, laser);
        }
        out.add(o.deviationsOut, formatDeviationCsv(set));
        deviationNote = fmt::format(
            "deviation set: {} = the mean bidirectional deviation (sign from the machine's kinematics: {:+.0f}), largest "
            "residual at the targets {:.3f} um{}{}; B{} = the mean reversal value B-bar = {:.3f} um (ISO 230-2; the axis "
            "reversal B = max |B_i| = {:.3f} um: B_i target by target only the two-column tables of --comp-out hold)\n",
            c.component, c.sensitivity, c.largestResidualUm,
            c.nodesOutside ? fmt::format(", {} table node(s) outside the targets hold the end targets' value", c.nodesOutside) : "",
            o.merge.empty() ? "" : fmt::format(", merged into {}", o.merge), r.axis, c.meanReversalUm, c.reversalUm);
        deviationNote += mergeLines;
    }
    std::string ini;
    if (!o.json.empty()) out.add(o.json, formatLaserJson(r, in.environmentStated, o.file));
    if (!o.compOut.empty()) {
        out.makeFolder(o.compOut);
        const auto add = [&](const std::string& name, const std::string& text) {
            out.add(OutputSet::fileIn(o.compOut, name, o.file), text);
        };
        if (linuxcnc) {
            namespace lc = controllers::linuxcnc;
            const std::string name = r.axis + ".comp";
            add(name, lc::formatCompTable(lc::compTableFromLaser(r), name));
            ini = lc::laserCompIniLines(r, o.joint, name);
        } else if (o.controller == "fanuc-30i") {
            add("CNCCOMP_LASER_" + r.axis + ".PRM", controllers::fanuc::fanucLaserPitch(r, o.axisNumber, referenceForward).file);
        } else if (o.controller == "siemens-840d") {
            const auto e = controllers::siemens::siemensLaserEec(r, fmt::format("AX{}", o.axisNumber), referenceForward);
            add("AX_EEC.INI", e.eec);
            add("AX_LASER_MD.INI", e.machineData);
        } else if (o.controller == "heidenhain-tnc") {
            // The column and sign of the axis' positioning component as `emit` writes it (laser_com.hpp).
            if (o.machine.empty())
                throw InputError("", 0, "--controller heidenhain-tnc needs --machine M.xml (the .COM column and sign of the "
                                        "axis' positioning component come from its description)");
            const MachineModel m = readMachineXml(o.machine);
            double far = 0;
            for (const LaserTargetResult& t : r.targets)
                if (std::abs(t.target) > std::abs(far)) far = t.target;
            AxisVector cmd = AxisVector::Zero(m.axisCount());
            const int axis = m.requireAxis(r.axis);
            cmd[axis] = far;
            const PositioningComponent pc = positioningComponent(m, r.axis, m.fromController(cmd)[axis]);
            const DeviationDef& d = m.deviations[static_cast<size_t>(pc.deviation)];
            const double sign = (d.side == Side::Tool ? -1.0 : 1.0) / pc.sensitivity;
            const auto c = controllers::heidenhain::heidenhainLaserCom(r, d.component + 1, sign, referenceForward);
            add(c.name, c.text);
        } else {
            add("LSEC_" + r.axis + ".LIS", controllers::isg::isgLaserLsec(r, o.axisNumber, r.axis));
        }
    }
    const std::vector<std::string> written = out.targets();  // commit() empties the set
    out.commit();
    for (const std::string& t : written) fmt::print("wrote {}\n", t);
    fmt::print("{}", deviationNote);
    if (!ini.empty()) fmt::print("add to the INI file:\n{}", ini);
}

const RegisterCommand reg([](CLI::App& app) {
    auto o = std::make_shared<Options>();
    auto* c = app.add_subcommand("laser", "Evaluate laser positioning runs of a linear axis (ISO 230-2) and write a "
                                          "LinuxCNC pitch-error table");
    c->add_option("--file", o->file, "laser CSV: target_mm, run, direction (+/-), deviation_um")
        ->required()
        ->check(CLI::ExistingFile);
    c->add_option("--axis", o->csv.axis, "axis name (when the file has no '# axis:' line)");
    c->add_option("--unit", o->csv.deviationUnit, "unit of the deviation column: um or mm")
        ->check(CLI::IsMember({"um", "mm"}));
    c->add_option("--target-column", o->csv.targetColumn, "name of the target column")->capture_default_str();
    c->add_option("--run-column", o->csv.runColumn, "name of the run column")->capture_default_str();
    c->add_option("--direction-column", o->csv.directionColumn, "name of the direction column")->capture_default_str();
    c->add_option("--deviation-column", o->csv.deviationColumn, "name of the deviation column (default deviation_<unit>)");
    c->add_option("--json", o->json, "write the figures as JSON");
    c->add_option("--comp-out", o->compOut, "folder for the LinuxCNC table <axis>.comp (COMP_FILE_TYPE 1)");
    c->add_option("--joint", o->joint, "LinuxCNC joint number of the axis (with --comp-out)")->check(CLI::NonNegativeNumber);
    c->add_option("--controller", o->controller,
                  "controller of the --comp-out files: linuxcnc (COMP_FILE), fanuc-30i (3620-3624 + data, 1851/1852), "
                  "siemens-840d (EEC + MD32450/32700), heidenhain-tnc (.COM + MP710), isg (bilateral LSEC list)")
        ->check(CLI::IsMember({"linuxcnc", "fanuc-30i", "siemens-840d", "heidenhain-tnc", "isg"}))
        ->capture_default_str();
    c->add_option("--axis-number", o->axisNumber, "the control's number of the axis (fanuc-30i A word, siemens-840d AXn, isg kopf.achs_nr)")
        ->check(CLI::PositiveNumber);
    c->add_option("--reference-direction", o->referenceDirection,
                  "direction of the axis' reference point approach (+ or -): the one-table controllers take that "
                  "direction's error and add the backlash in the other")
        ->check(CLI::IsMember({"+", "-"}))
        ->capture_default_str();
    c->add_option("--machine", o->machine, "machine description XML (with --deviations-out)")->check(CLI::ExistingFile);
    c->add_option("--deviations-out", o->deviationsOut,
                  "deviation CSV with the axis' positioning component E<axis><axis> (the mean bidirectional deviation)");
    c->add_option("--merge", o->merge, "deviation CSV to merge into (its other deviations kept; with --deviations-out)")
        ->check(CLI::ExistingFile);
    c->callback([o] { run(*o); });
});

}  // namespace
}  // namespace cnccomp::cli
