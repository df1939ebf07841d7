#include "cnccomp/identification/plan_observations.hpp"

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/identification/dbb5_observation.hpp"
#include "cnccomp/identification/rtest_observation.hpp"
#include "cnccomp/identification/absolute_ballbar_observation.hpp"

namespace cnccomp::identification {
using namespace cnccomp::io;
using namespace cnccomp::measurement;

Observations planObservations(const MachineModel& m, const MeasurementPlan& plan, const PlanMeasurements& data) {
    if (plan.runCount() == 0) throw ModelError("the plan has no runs");
    Observations all;
    const auto append = [&](Observations more) {
        for (auto& o : more) all.push_back(std::move(o));
    };
    const auto need = [](bool loaded, size_t have, size_t runs, const char* kind) {
        if (!loaded || have != runs)
            throw ModelError(fmt::format("the measurements of the plan's {} runs were not read", kind));
    };
    if (!plan.runs.empty()) {
        need(data.loaded.ballbar, data.ballbar.size(), plan.runs.size(), "ball-bar");
        std::vector<BallbarTrace> traces;
        for (const MeasuredTrace& t : data.ballbar) traces.push_back(t.trace);
        append(ballbarObservations(m, plan.runs, traces));
    }
    if (!plan.absoluteRuns.empty()) {
        need(data.loaded.absolute, data.absolute.size(), plan.absoluteRuns.size(), "absolute ball-bar");
        append(absoluteBallbarObservations(m, plan.absoluteRuns, data.absolute));
    }
    if (!plan.rtestRuns.empty()) {
        need(data.loaded.rtest, data.rtest.size(), plan.rtestRuns.size(), "R-test");
        append(rtestObservations(m, plan.rtestRuns, data.rtest));
    }
    if (!plan.dbb5Runs.empty()) {
        need(data.loaded.dbb5, data.dbb5.size(), plan.dbb5Runs.size(), "DBB5");
        append(dbb5Observations(m, plan.dbb5Runs, data.dbb5));
    }
    return all;
}

}  // namespace cnccomp::identification
