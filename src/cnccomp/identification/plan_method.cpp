#include "cnccomp/identification/plan_method.hpp"

#include <algorithm>
#include <map>
#include <set>
#include <tuple>

#include <fmt/format.h>

#include "cnccomp/error.hpp"

namespace cnccomp::identification {
using namespace cnccomp::measurement;

const char* planMethodName(PlanMethod m) {
    switch (m) {
        case PlanMethod::Ballbar: return "ball-bar";
        case PlanMethod::HeadPatterns: return "head-patterns";
        case PlanMethod::RtestLocation: return "rtest-location";
        case PlanMethod::RtestTables: return "rtest-tables";
        case PlanMethod::Dbb5: return "dbb5";
        case PlanMethod::Mixed: return "mixed";
        case PlanMethod::LinearCircle: return "circle";
        case PlanMethod::Sphere: return "sphere";
    }
    return "?";
}

const char* planMethodMeasures(PlanMethod m) {
    switch (m) {
        case PlanMethod::Ballbar: return "location errors of the rotary axes, squareness, spindle offsets (ball-bar circles)";
        case PlanMethod::HeadPatterns: return "errors of a tilting head over its angle and the orientation of its axis (absolute ball bar, two tool lengths)";
        case PlanMethod::RtestLocation: return "location errors of the rotary axes and squareness of the slides (R-test trajectories)";
        case PlanMethod::RtestTables: return "six errors of each rotary axis of a cradle over its angle (R-test, three balls)";
        case PlanMethod::Dbb5: return "location errors of the rotary axes and squareness of the slides (DBB5 circles), ISO 230-4 figures";
        case PlanMethod::Mixed: return "any subset of the deviations from runs of several kinds";
        case PlanMethod::LinearCircle:
            return "diagnostics of the linear axes (centring, squareness, scale mismatch, straightness, backlash, reversal "
                   "spikes, lateral play, cyclic error, servo mismatch) from ball-bar circles, ISO 230-4 figures";
        case PlanMethod::Sphere:
            return "location errors of the rotary axes from the centres of a calibration sphere probed at rotary-axis poses";
    }
    return "?";
}

const char* planMethodFormulas(PlanMethod m) {
    switch (m) {
        case PlanMethod::Ballbar:
            return "eccentricity formulas (17)-(28) of the ball-bar identification of geometric deviations of "
                   "multi-tasking machine tools with a swivel tool spindle head ([MultiTasking])";
        case PlanMethod::HeadPatterns:
            return "eq. (7), (9), (16), (21) of Fan, Wu & Li, 'A novel geometric error identification methodology for "
                   "the tilting head of five-axis machine tools based on double ball bar'";
        case PlanMethod::RtestLocation:
            return "circle, line and ellipse fits with eq. (2) of Moravek, Horejs & Bach, 'Set of geometric errors "
                   "evaluation based on R-test measurement' (MM Science Journal 2019)";
        case PlanMethod::RtestTables:
            return "per-angle solution of eq. (1)-(7) of 'A simple modeling method to identify the kinematic errors of "
                   "machine tool rotary table' (Zhejiang University)";
        case PlanMethod::Dbb5:
            return "eq. (1)-(3), (6)-(7) and the elliptic term of the linear circles of Ibaraki, Kakino, Akai, Takayama "
                   "& Yamaji, 'Identification of motion error sources on five-axis machine tools by ball-bar "
                   "measurements (1st report)' (DBB5)";
        case PlanMethod::Mixed: return "none (runs of several kinds)";
        case PlanMethod::LinearCircle: return "none (the diagnostics are least-squares parameters of the exact model)";
        case PlanMethod::Sphere: return "none (the sphere centres are fitted by least squares on the exact model)";
    }
    return "?";
}

namespace {

/// Largest number of distinct ball positions among R-test runs that sweep one axis alone, per axis.
int ballsPerSweptAxis(const MeasurementPlan& plan) {
    std::map<std::string, std::set<std::tuple<double, double, double>>> balls;
    for (const RtestRun& r : plan.rtestRuns) {
        std::vector<std::string> moving;
        for (const RotarySweep& s : r.sweeps)
            if (s.startDeg != s.endDeg) moving.push_back(s.axis);
        if (moving.size() == 1) balls[moving[0]].insert({r.ball.x(), r.ball.y(), r.ball.z()});
    }
    int most = 0;
    for (const auto& [axis, set] : balls) most = std::max(most, static_cast<int>(set.size()));
    return most;
}

std::string kindsOf(const MeasurementPlan& plan) {
    std::string s;
    const auto add = [&](size_t n, const char* what) {
        if (n) s += fmt::format("{}{} {}", s.empty() ? "" : ", ", n, what);
    };
    add(plan.runs.size(), "<run>");
    add(plan.absoluteRuns.size(), "<absolute-run>");
    add(plan.rtestRuns.size(), "<rtest>");
    add(plan.dbb5Runs.size(), "<dbb5>");
    add(plan.circleRuns.size(), "<circle>");
    add(plan.sphereRuns.size(), "<sphere>");
    return s;
}

}  // namespace

PlanMethod classifyPlan(const MeasurementPlan& plan) {
    if (plan.runCount() == 0) throw ModelError("the plan has no runs");
    const int kinds = !plan.runs.empty() + !plan.absoluteRuns.empty() + !plan.rtestRuns.empty() + !plan.dbb5Runs.empty() +
                      !plan.circleRuns.empty() + !plan.sphereRuns.empty();
    if (kinds > 1 && !plan.sphereRuns.empty())
        throw ModelError(fmt::format("the plan has sphere probing runs (<sphere>) and other runs ({}): the probe's result "
                                     "file is identified on its own; put the <sphere> runs in a plan of their own",
                                     kindsOf(plan)));
    if (!plan.sphereRuns.empty()) return PlanMethod::Sphere;
    if (kinds > 1 && !plan.circleRuns.empty())
        throw ModelError(fmt::format("the plan has circles of the linear axes (<circle>) and other runs ({}): the circles' "
                                     "diagnostics are identified on their own; put the <circle> runs in a plan of their own",
                                     kindsOf(plan)));
    if (kinds > 1) return PlanMethod::Mixed;
    if (!plan.circleRuns.empty()) return PlanMethod::LinearCircle;
    if (!plan.runs.empty()) return PlanMethod::Ballbar;
    if (!plan.absoluteRuns.empty()) return PlanMethod::HeadPatterns;
    if (!plan.dbb5Runs.empty()) return PlanMethod::Dbb5;
    return ballsPerSweptAxis(plan) >= 3 ? PlanMethod::RtestTables : PlanMethod::RtestLocation;
}

PlanMethod choosePlanMethod(const MeasurementPlan& plan, const std::string& name) {
    const PlanMethod fits = classifyPlan(plan);
    if (name.empty() || name == "auto") return fits;
    PlanMethod want = PlanMethod::Mixed;
    bool known = false;
    for (PlanMethod m : {PlanMethod::Ballbar, PlanMethod::HeadPatterns, PlanMethod::RtestLocation, PlanMethod::RtestTables,
                         PlanMethod::Dbb5, PlanMethod::Mixed, PlanMethod::LinearCircle, PlanMethod::Sphere})
        if (name == planMethodName(m)) want = m, known = true;
    if (!known)
        throw ModelError(fmt::format("unknown measurement '{}' (ball-bar, head-patterns, rtest-location, rtest-tables, "
                                     "dbb5, mixed, circle, sphere)",
                                     name));
    if (want == fits || (want == PlanMethod::Mixed && fits != PlanMethod::LinearCircle && fits != PlanMethod::Sphere))
        return want;
    // The two R-test methods read the same kind of run.
    if (fits == PlanMethod::RtestTables && want == PlanMethod::RtestLocation) return want;
    if (fits == PlanMethod::RtestLocation && want == PlanMethod::RtestTables)
        throw ModelError(fmt::format("'{}' needs R-test runs that sweep one axis at a time with the ball at three or more "
                                     "places; this plan ({}) fits '{}'",
                                     name, kindsOf(plan), planMethodName(fits)));
    throw ModelError(fmt::format("the plan ({}) does not fit '{}' ({}); it fits '{}' ({})", kindsOf(plan), name,
                                 planMethodMeasures(want), planMethodName(fits), planMethodMeasures(fits)));
}

std::pair<std::string, std::string> tableRotaryAxes(const MachineModel& m) {
    std::vector<std::string> rot;
    for (const Link& l : m.workpiece.links)
        if (l.kind == AxisKind::Rotary) rot.push_back(l.name);
    if (rot.size() < 2) return {"", ""};
    return {rot[0], rot[1]};
}

}  // namespace cnccomp::identification
