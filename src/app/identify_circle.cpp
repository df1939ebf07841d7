// `cnccomp identify` on a plan of ball-bar circles of the linear axes (<circle> runs, ISO 230-4): the method of the
// registry (identify_registry.hpp) that routes them to linear_circle_identify.hpp.
#include <fmt/format.h>

#include "app/identify_registry.hpp"
#include "cnccomp/error.hpp"

namespace cnccomp::app {
using namespace cnccomp::identification;
using namespace cnccomp::measurement;

namespace {

void checkCircles(const MethodRequest& r) {
    if (r.formulas)
        throw ModelError("the circles of the linear axes have no paper's formulas here: their diagnostics are least-squares "
                         "parameters of the exact model (leave --method at least-squares)");
    if (!r.params.empty() || !r.bounds.empty() || !r.start.empty() || r.monteCarlo > 0 || r.solver != SolverChoice{})
        throw ModelError("--params, --bounds, --start, --monte-carlo and --solver do not apply to the circles of the linear "
                         "axes: every diagnostic of the model is estimated, Gauss-Newton on the exact model");
    if (!r.eccentricities.empty()) throw ModelError("--eccentricities is for the ball-bar formulas only; this plan is 'circle'");
    if (r.traces.empty()) throw ModelError("give the measured runs with --traces DIR (one <run>.csv per <circle> of the plan)");
    if (!r.outer.empty() || !r.inner.empty() || !r.volumetricRun.empty() || r.components)
        throw ModelError("--outer, --inner, --volumetric and --components belong to rotary-axis plans, not to the circles of "
                         "the linear axes");
}

MeasurementKinds circleReads(const MethodRequest&) {
    MeasurementKinds k;
    k.circles = true;
    return k;
}

IdentificationSummary identifyCircles(const MethodRequest& r) {
    LinearCircleSettings settings;
    settings.rankTolerance = r.rankTolerance;
    settings.maxIterations = r.maxIterations;
    const MachineModel& m = *r.machine;
    LinearCircleIdentification id = identifyLinearCircleRuns(m, r.plan->circleRuns, r.data->circles, settings);
    IdentificationSummary out{id.deviations, std::nullopt, {}, "", std::nullopt, std::nullopt, std::nullopt};
    int samples = 0;
    for (const LinearCircleRunResult& run : id.runs) samples += run.fit.observations;
    std::string written;
    for (const LinearCircleDeviation& d : id.written) written += fmt::format("{}{}", written.empty() ? "" : ", ", d.name);
    for (const LinearCircleReversal& v : id.reversals) written += fmt::format("{}B{}", written.empty() ? "" : ", ", v.axis);
    out.summary = fmt::format("identified the diagnostics of {} circle(s) of the linear axes of '{}' (ISO 230-4 ball bar, "
                              "least squares on the exact circle model, {} samples); deviation set: {}",
                              id.runs.size(), m.name, samples, written.empty() ? "nothing written" : written);
    out.circles = std::move(id);
    return out;
}

}  // namespace

IdentificationMethod linearCircleMethod() {
    return {planMethodName(PlanMethod::LinearCircle), {PlanMethod::LinearCircle},
            "ball-bar circles of the linear axes (ISO 230-4): diagnostics ranked by their share of the circularity",
            circleReads, checkCircles, identifyCircles};
}

}  // namespace cnccomp::app
