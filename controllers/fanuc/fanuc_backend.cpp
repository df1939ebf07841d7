// Backend "fanuc-30i": one parameter file (CNCCOMP.PRM) with the 5-axis TCP machine configuration and
// offsets (tcp_parameters.hpp) and the stored pitch error compensation (pitch_error.hpp). Apply model: the
// 30i tool centre point control (G43.4) on the kinematics the parameters describe — the programmed commands'
// nominal tool pose is reached on it — then the pitch error correction interpolated at each axis position.
#include "controllers/fanuc/fanuc_backend.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/text_util.hpp"
#include "controllers/common/axis_table.hpp"
#include "controllers/common/header.hpp"
#include "controllers/common/set_backlash.hpp"
#include "controllers/fanuc/laser_pitch.hpp"
#include "controllers/fanuc/tcp_parameters.hpp"

namespace cnccomp::controllers::fanuc {
using namespace cnccomp::controllers::common;
using namespace cnccomp::io;

EmitResult emitFiles(const EmitRequest& request, const PitchOptions& o) {
    const MachineModel& m = request.machine;
    const DeviationSet& d = request.deviations;
    d.requireMachine(m);
    if (!d.values.allFinite()) throw ModelError("the deviation set holds a value that is not a finite number");
    const TcpParameters tcp = tcpFromMachine(m, d.values);
    const PitchPlan pitch = pitchFromDeviations(m, d, o);
    EmitResult r;
    for (size_t di = 0; di < m.deviations.size(); ++di) {
        if (!d.present[di]) continue;
        const DeviationDef& def = m.deviations[di];
        if (def.kind != DeviationKind::Location) continue;
        const Link& l = m.chain(def.side).links[def.link];
        if (def.isAngle()) {
            const bool zero = l.kind == AxisKind::Rotary && std::abs(Vec3::Unit(def.component - 3).dot(l.direction)) > 1 - 1e-9;
            r.notCompensated.push_back(
                {def.name, l.kind == AxisKind::Linear
                               ? "squareness: the 30i TCP takes orthogonal linear axes (straightness/3-D compensation "
                                 "parameters not public [G])"
                           : zero ? "zero position of a rotary axis: no TCP parameter (shift its reference position, "
                                    "parameter 1850, by hand [G])"
                                  : "tilt of a rotary axis or of the spindle: the 30i TCP parameters hold none"});
            continue;
        }
        std::string where;
        if (l.kind == AxisKind::Rotary) where = m.axisSide(l.axisIndex) == Side::Tool ? "tool rotary axis position (19709-19714)" : "rotary table position (19700-19705)";
        else if (l.kind == AxisKind::Fixed) where = def.side == Side::Tool ? "tool axis offset (19709-19711)" : "workpiece zero (1220)";
        else where = "controlled point / workpiece zero (1220)";
        r.compensated.push_back({def.name, fmt::format("5-axis TCP: {}", where)});
    }
    r.compensated.insert(r.compensated.end(), pitch.compensated.begin(), pitch.compensated.end());
    r.notCompensated.insert(r.notCompensated.end(), pitch.notCompensated.begin(), pitch.notCompensated.end());
    // Reversal values → backlash 1851 / 1852 (the laser route's writer, laser_pitch.hpp; set_backlash.hpp).
    std::map<int, long> backlashUnits;
    for (const AxisBacklash& b : backlashOfSet(request)) {
        const long units = backlashDetectionUnits(b.backlashUm, o.unit);
        backlashUnits[controllerAxisNumber(m, b.axis)] = units;
        r.compensated.push_back({"B" + b.name, fmt::format("backlash 1851/1852 A{} = {} detection units = {:.4f} mm (= -B{} = {:.3f} um; "
                                                           "reference return in + [G])",
                                                           controllerAxisNumber(m, b.axis), units, units * o.unit, b.name,
                                                           b.backlashUm)});
    }

    std::string axes;
    for (int a : controllerAxisOrder(m)) axes += fmt::format("{}A{} = {}", axes.empty() ? "" : ", ", controllerAxisNumber(m, a), m.axisNames[a]);
    const std::vector<std::string> notes = {
        "controlled axes: " + axes + "; path 1; increment system IS-C (0.0001 mm / 0.0001 deg) [G]",
        frameNote(m),
        "absolute values: 19680-19714 and 1220 replace the control's values (machine coordinates at all axes 0, A-79348E); "
        "they are not deltas to add",
        fmt::format("machine type 19680 = {}; 1220 moves the workpiece datum onto the measured axis lines (leave it out if "
                    "the datum is probed again)",
                    tcp.type),
        "pitch data (B-63980EN p.100): point k holds the increment of the section ending at (k - 3620) x 3624 from the "
        "reference position (machine 0); rotary: 3621 = 3620 and point 3620 = point 3622",
        "pitch data sign: correction added to the command (= -error) [G]; linear inside a section [G]",
        "line format N<number>Q1L1P (path), N<number>Q1A<n>P (axis), N1<point>Q0P (pitch data) [G: confirm on the control]",
        "power off/on and a reference return after loading",
    };
    const std::string header = formatHeader(makeHeaderInfo(request, "Fanuc Series 30i (5-axis TCP parameters, pitch error compensation)",
                                                            r, notes),
                                            "(", ")");
    std::vector<Parameter> lines = tcpLines(m, tcp);
    const auto pl = pitchLines(m, pitch.tables);
    lines.insert(lines.end(), pl.begin(), pl.end());
    addBacklashParameters(lines, backlashUnits);
    // Parameters by number, then the pitch error data.
    std::stable_sort(lines.begin(), lines.end(), [](const Parameter& a, const Parameter& b) {
        return std::make_pair(a.q == 0, a.number) < std::make_pair(b.q == 0, b.number);
    });
    r.files.push_back({kParameterFile, formatParameterFile(header, lines)});
    return r;
}

FanucCompensation::FanucCompensation(const MachineModel& m, std::unique_ptr<const ControllerModel> tcp,
                                     std::vector<PitchTable> pitch, double unit)
    : machine_(&m), tcp_(m, std::move(tcp)), pitch_(std::move(pitch)), unit_(unit) {}

AxisVector FanucCompensation::driveCommands(const AxisVector& programmed) const {
    return driveCommandsForTool(programmed, tcp_.toolLength());
}

AxisVector FanucCompensation::driveCommandsForTool(const AxisVector& programmed, double toolLength) const {
    const AxisVector q = tcp_.solve(programmed, toolLength);
    AxisVector out = q;
    // Pitch error compensation acts on the machine position of each axis (the controller's coordinates).
    const AxisVector p = machine_->toController(q);
    for (const PitchTable& t : pitch_) {
        const double scale = positionScale(machine_->axisLink(t.axis));
        out[t.axis] += t.correction(p[t.axis] * scale, unit_) / scale;
    }
    return out;
}

AxisVector FanucCompensation::driveCommandsMoving(const AxisVector& programmed, double toolLength, const AxisVector& motion) const {
    return withBacklashOffsets(driveCommandsForTool(programmed, toolLength), backlash, motion);
}

std::unique_ptr<FanucCompensation> readFiles(const MachineModel& m, const std::vector<OutputFile>& files) {
    const OutputFile* prm = nullptr;
    for (const OutputFile& f : files) {
        if (f.name != kParameterFile) throw InputError(f.name, 0, fmt::format("not a fanuc-30i file (expected {})", kParameterFile));
        prm = &f;
    }
    if (!prm) throw InputError(kParameterFile, 0, "missing: the parameter file is needed");
    const ParameterFile f = parseParameterFile(prm->name, prm->content);
    for (const Parameter& p : f.parameters) {
        const bool known = p.q == 0 || p.number == 1220 || p.number == 1851 || p.number == 1852 || (p.number >= 3620 && p.number <= 3625) || p.number == 19666 ||
                           (p.number >= 19680 && p.number <= 19714);
        if (!known) throw InputError(f.path, p.line, fmt::format("parameter {} is not one cnccomp writes or models", p.number));
    }
    const TcpParameters tcp = tcpFromFile(m, f);
    std::vector<PitchTable> pitch = pitchFromFile(m, f);
    std::vector<ChainElement> wp, tool;
    tcpChains(m, tcp, wp, tool);
    std::unique_ptr<const ControllerModel> model;
    try {
        model = std::make_unique<ControllerModel>(m, wp, tool);
    } catch (const ModelError& e) {
        throw InputError(f.path, f.find(19680) ? f.find(19680)->line : 0, e.what());
    }
    auto out = std::make_unique<FanucCompensation>(m, std::move(model), std::move(pitch), PitchOptions{}.unit);
    // 1851 (cutting feed: the test programs' moves) per axis, detection units → mm (deg for a rotary axis).
    if (const Parameter* b = f.find(1851)) {
        out->backlash.assign(static_cast<size_t>(m.axisCount()), 0.0);
        for (const auto& [number, text] : b->values) {
            int axis = -1;
            for (int a = 0; a < m.axisCount(); ++a)
                if (controllerAxisNumber(m, a) == number) axis = a;
            const auto v = parseNumber(text);
            if (axis < 0 || !v) throw InputError(f.path, b->line, fmt::format("1851 A{}: expected an axis of the machine and a count", number));
            out->backlash[static_cast<size_t>(axis)] = *v * PitchOptions{}.unit / positionScale(m.axisLink(axis));
        }
    }
    return out;
}

namespace {

class FanucBackend final : public Backend {
public:
    std::string_view name() const override { return "fanuc-30i"; }
    std::string_view description() const override {
        return "Fanuc 30i: parameter file with the 5-axis TCP offsets (19680-19714, 1220) from the pivot errors and "
               "stored pitch error compensation (3620-3625 + data)";
    }
    EmitResult emit(const EmitRequest& request) const override { return emitFiles(request, PitchOptions{}); }
    std::vector<std::string> checks() const override {
        return {"increment system IS-C (0.0001 mm / deg): the P values of 19700-19714 and the pitch data are written for it",
                "pitch data sign: a positive value moves the axis positive (cnccomp writes -error); check one point with "
                "a laser before loading all",
                "pitch error output is interpolated inside a section by cnccomp's model; a control that outputs it as a "
                "step at the point leaves up to half a section's change",
                "pitch limits: 128 intervals per axis, 1024 points in all, data within +-127 (3623 magnification <= 100)",
                "the parameter tape format (N....Q1L1P / A<n>P / Q0P lines) reads in on your control's I/O settings",
                "axis numbers A1.. in the order X Y Z A B C are the control's controlled-axis numbers"};
    }
    std::unique_ptr<AppliedCompensation> apply(const MachineModel& machine,
                                               const std::vector<OutputFile>& files) const override {
        return readFiles(machine, files);
    }
};

const RegisterBackend registration(std::make_unique<FanucBackend>());

}  // namespace
}  // namespace cnccomp::controllers::fanuc
