#include "cnccomp/io/plan_measurements_io.hpp"

#include <filesystem>

#include "cnccomp/io/output_set.hpp"
#include "cnccomp/io/probe_log.hpp"
#include "cnccomp/io/rtest_csv.hpp"
#include "cnccomp/io/trace_csv.hpp"

namespace cnccomp::io {
using namespace cnccomp::measurement;

PlanMeasurements loadPlanMeasurements(const MachineModel& m, const MeasurementPlan& plan, const std::string& dir,
                                      const MeasurementKinds& kinds, const std::string& probeLog) {
    PlanMeasurements out;
    out.folder = dir;
    out.loaded = kinds;
    const auto file = [&](const std::string& name) { return (std::filesystem::path(dir) / (name + ".csv")).string(); };
    if (kinds.ballbar && !plan.runs.empty()) out.ballbar = importRunTraces(dir, plan.runs, m.name);
    if (kinds.absolute && !plan.absoluteRuns.empty())
        for (MeasuredTrace& t : importRunTraces(dir, plan.absoluteRuns)) out.absolute.push_back(std::move(t.trace));
    if (kinds.rtest && !plan.rtestRuns.empty()) out.rtest = readRtestTraces(dir, m, plan.rtestRuns);
    if (kinds.dbb5)
        for (const Dbb5Run& r : plan.dbb5Runs) out.dbb5.push_back(readTraceCsv(file(r.name)));
    if (kinds.circles)
        for (const LinearCircleRun& run : plan.circleRuns) {
            run.validate();
            linearCircleCentreCommands(m, run);  // the machine has the axes
            out.circles.push_back(importLinearCircleTrace(OutputSet::fileIn(dir, run.name + ".csv"), run, m.name));
        }
    if (kinds.probes) out.probes = readProbeLog((std::filesystem::path(dir) / probeLog).string(), m);
    return out;
}

}  // namespace cnccomp::io
