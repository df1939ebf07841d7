#include "cnccomp/identification/plan_observations.hpp"

#include <filesystem>

#include "cnccomp/error.hpp"
#include "cnccomp/identification/dbb5_observation.hpp"
#include "cnccomp/identification/rtest_observation.hpp"
#include "cnccomp/identification/absolute_ballbar_observation.hpp"
#include "cnccomp/io/rtest_csv.hpp"
#include "cnccomp/io/trace_csv.hpp"

namespace cnccomp {

Observations planObservations(const MachineModel& m, const MeasurementPlan& plan, const std::string& dir) {
    if (plan.runCount() == 0) throw ModelError("the plan has no runs");
    Observations all;
    const auto append = [&](Observations more) {
        for (auto& o : more) all.push_back(std::move(o));
    };
    if (!plan.runs.empty()) append(ballbarObservations(m, plan.runs, readRunTraces(dir, plan.runs)));
    if (!plan.absoluteRuns.empty())
        append(absoluteBallbarObservations(m, plan.absoluteRuns, readRunTraces(dir, plan.absoluteRuns)));
    if (!plan.rtestRuns.empty()) append(rtestObservations(m, plan.rtestRuns, readRtestTraces(dir, m, plan.rtestRuns)));
    if (!plan.dbb5Runs.empty()) {
        std::vector<BallbarTrace> traces;
        for (const Dbb5Run& r : plan.dbb5Runs)
            traces.push_back(readTraceCsv((std::filesystem::path(dir) / (r.name + ".csv")).string()));
        append(dbb5Observations(m, plan.dbb5Runs, traces));
    }
    return all;
}

}  // namespace cnccomp
