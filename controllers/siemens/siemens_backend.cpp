#include "controllers/siemens/siemens_backend.hpp"

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/text_util.hpp"
#include "controllers/common/axis_table.hpp"
#include "controllers/common/files.hpp"
#include "controllers/common/header.hpp"
#include "controllers/common/set_backlash.hpp"
#include "controllers/siemens/laser_eec.hpp"
#include "controllers/siemens/compensation_tables.hpp"
#include "controllers/siemens/kinematic_chain.hpp"

namespace cnccomp::controllers::siemens {
using namespace cnccomp::controllers::common;
using namespace cnccomp::io;

EmitResult emitFiles(const EmitRequest& request, const Options& o) {
    const MachineModel& m = request.machine;
    const Plan plan = makePlan(m, request.deviations, o);
    EmitResult r;
    r.compensated = plan.compensated;
    r.notCompensated = plan.notCompensated;
    // Reversal values → MD32450 $MA_BACKLASH (the laser route's line, laser_eec.hpp; set_backlash.hpp).
    std::string backlash;
    for (const AxisBacklash& b : backlashOfSet(request)) {
        backlash += backlashMachineData(axisName(m, b.axis), b.backlashUm * 1e-3);
        r.compensated.push_back({"B" + b.name, fmt::format("MD32450 $MA_BACKLASH[0,{}] = {:.6f} mm (= -B{}) in {}", axisName(m, b.axis),
                                                           b.backlashUm * 1e-3, b.name, kBacklashFile)});
    }
    std::string axes;
    for (int a : controllerAxisOrder(m)) axes += fmt::format("{}{} = {}", axes.empty() ? "" : ", ", axisName(m, a), m.axisNames[a]);
    std::vector<std::string> notes = {
        "machine axes: " + axes + " (MD10000 names as written; rename if yours differ)",
        "units: mm and degrees",
        frameNote(m),
        "absolute values: the kinematic chain ($NK_OFF_DIR offsets, $NK_A_OFF) replaces the NCK's chain and the CEC/EEC "
        "tables replace its tables, positions in machine coordinates; nothing is a delta to add",
        "kinematic chain: root element \"ROOT\" named by MD16800 $MN_ROOT_KIN_ELEM_NAME (set in the file [G: needs the "
        "access level]); MD18880 $MN_MM_MAXNUM_KIN_CHAIN_ELEM >= the elements written",
        "CEC: the table value is added to the output axis (correction = -error) [G: sign not confirmed]",
        "CEC: enable with MD18342 MM_CEC_MAX_POINTS[t] >= points, SD41300 CEC_TABLE_ENABLE[t]=1, "
        "MD32710 CEC_ENABLE=1 [G]",
        "EEC: the value is the positioning error; a positive value moves the axis negative (K3); MD32700 ENC_COMP_ENABLE=1",
        "kinematic chain: element meaning (OFFSET, ROT_CONST, AXIS_* with $NK_A_OFF) and branching with "
        "$NK_PARALLEL at ROOT as read by cnccomp [G: confirm with K12 for your NCK version]",
        "linear axes are written orthogonal in the chain; their squareness is in the CEC tables",
    };
    const std::string header =
        formatHeader(makeHeaderInfo(request, "Siemens Sinumerik 840D sl (CEC, EEC, kinematic chain for TRAORI)", r, notes),
                     "; ");
    r.files.push_back({kChainFile, formatKinematicChain(m, plan, o, header)});
    if (!plan.cec.empty()) r.files.push_back({kCecFile, formatCec(m, plan.cec, header)});
    if (!plan.eec.empty()) r.files.push_back({kEecFile, formatEec(m, plan.eec, header)});
    if (!backlash.empty())
        r.files.push_back({kBacklashFile, "%_N_CNCCOMP_BACKLASH_INI\n" + header +
                                              "; MD32450 BACKLASH (mm, first measuring system) = -B<axis>, the deviation set's reversal "
                                              "value: positive when the encoder leads the slide (lost motion, the normal case; "
                                              "808D Parameter Manual p.228); active after the reference point approach; NewConfig\n" +
                                              backlash + "M17\n"});
    return r;
}

SiemensCompensation::SiemensCompensation(const MachineModel& m, std::unique_ptr<const ControllerModel> chain,
                                         std::vector<CecTable> cec, std::vector<EecTable> eec)
    : machine_(&m), tcp_(m, std::move(chain)), cec_(std::move(cec)), eec_(std::move(eec)) {}

AxisVector SiemensCompensation::driveCommands(const AxisVector& programmed) const {
    return driveCommandsForTool(programmed, tcp_.toolLength());
}

AxisVector SiemensCompensation::driveCommandsForTool(const AxisVector& programmed, double toolLength) const {
    const AxisVector q = tcp_.solve(programmed, toolLength);
    // CEC and EEC tables are looked up at the machine positions (the NCK's machine coordinates, K3).
    const AxisVector p = machine_->toController(q);
    AxisVector out = q;
    for (const CecTable& c : cec_) {
        const double in = p[c.input] * positionScale(machine_->axisLink(c.input));
        out[c.output] += c.table.at(in) / positionScale(machine_->axisLink(c.output));
    }
    for (const EecTable& e : eec_) {
        const double scale = positionScale(machine_->axisLink(e.axis));
        out[e.axis] -= e.table.at(p[e.axis] * scale) / scale;
    }
    return out;
}

std::unique_ptr<SiemensCompensation> readFiles(const MachineModel& m, const std::vector<OutputFile>& files) {
    const OutputFile* chain = nullptr;
    std::vector<CecTable> cec;
    std::vector<EecTable> eec;
    const OutputFile* backlashFile = nullptr;
    for (const OutputFile& f : files) {
        if (f.name == kChainFile) chain = &f;
        else if (f.name == kCecFile) cec = parseCec(m, f.name, f.content);
        else if (f.name == kEecFile) eec = parseEec(m, f.name, f.content);
        else if (f.name == kBacklashFile) backlashFile = &f;
        else throw InputError(f.name, 0, fmt::format("not a siemens-840d file (expected {}, {}, {} or {})", kChainFile, kCecFile,
                                                     kEecFile, kBacklashFile));
    }
    if (!chain) throw InputError(kChainFile, 0, "missing: the kinematic chain file is needed for TRAORI");
    const ParsedChain pc = parseKinematicChain(m, chain->name, chain->content);
    std::unique_ptr<const ControllerModel> model;
    try {
        model = std::make_unique<ControllerModel>(m, pc.workpiece, pc.tool);
    } catch (const ModelError& e) {
        throw InputError(chain->name, 0, e.what());
    }
    auto out = std::make_unique<SiemensCompensation>(m, std::move(model), std::move(cec), std::move(eec));
    if (backlashFile) {  // "$MA_BACKLASH[0,AXk]=value" lines; ';' comments, the %_N_ line and M17
        out->backlash.assign(static_cast<size_t>(m.axisCount()), 0.0);
        for (const TextLine& l : splitLines(backlashFile->content)) {
            const std::string_view t = trim(l.text);
            if (t.empty() || t.front() == ';' || t.front() == '%' || t == "M17") continue;
            const size_t close = t.find(']'), eq = t.find('=');
            int axis = -1;
            if (t.starts_with("$MA_BACKLASH[0,") && close != std::string_view::npos && eq == close + 1)
                for (int a = 0; a < m.axisCount(); ++a)
                    if (axisName(m, a) == t.substr(15, close - 15)) axis = a;
            const auto v = eq == std::string_view::npos ? std::nullopt : parseNumber(t.substr(eq + 1));
            if (axis < 0 || !v)
                throw InputError(backlashFile->name, l.number, "expected $MA_BACKLASH[0,<axis of the machine>]=<mm>, a comment or M17");
            out->backlash[static_cast<size_t>(axis)] = *v / positionScale(m.axisLink(axis));
        }
    }
    return out;
}

AxisVector SiemensCompensation::driveCommandsMoving(const AxisVector& programmed, double toolLength, const AxisVector& motion) const {
    return withBacklashOffsets(driveCommandsForTool(programmed, toolLength), backlash, motion);
}

namespace {

class SiemensBackend final : public Backend {
public:
    std::string_view name() const override { return "siemens-840d"; }
    std::string_view description() const override {
        return "Sinumerik 840D sl: CEC tables (squareness, cross-axis), EEC tables (positioning), kinematic chain "
               "($NK_) with the rotary-axis locations for TRAORI";
    }
    EmitResult emit(const EmitRequest& request) const override { return emitFiles(request, Options{}); }
    std::vector<std::string> checks() const override {
        return {"CEC sign: cnccomp writes the correction to add to the output axis (-error); move the input axis with "
                "one table loaded and watch the output axis go the right way",
                "kinematic chain element meanings (OFFSET, ROT_CONST, AXIS_LIN/AXIS_ROT with $NK_A_OFF) as cnccomp reads "
                "K7/K12; check the chain in the HMI's kinematic view before activating TRAORI",
                "MD16800 $MN_ROOT_KIN_ELEM_NAME = \"ROOT\" is set by the file; if the access level refuses it, set it "
                "by hand, then NewConfig",
                "machine axis names AX1.. in the order X Y Z A B C; rename to your MD10000 names",
                "CEC limits: MD18342 MM_CEC_MAX_POINTS per table, 62 tables [G]; EEC: MD38000 MM_ENC_COMP_MAX_POINTS"};
    }
    std::unique_ptr<AppliedCompensation> apply(const MachineModel& machine,
                                               const std::vector<OutputFile>& files) const override {
        return readFiles(machine, files);
    }
};

const RegisterBackend registration(std::make_unique<SiemensBackend>());

}  // namespace
}  // namespace cnccomp::controllers::siemens
