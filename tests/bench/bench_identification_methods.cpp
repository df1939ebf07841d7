// The identification methods on their sample plans (noise-free data): R-test location fits with refinement, head-pattern
// formulas and least squares, DBB5 formulas, per-angle and least-squares R-test tables.
#include <benchmark/benchmark.h>

#include "cnccomp/identification/rtest_location_fits.hpp"
#include "cnccomp/identification/tilting_head_errors.hpp"
#include "cnccomp/identification/dbb5_location_errors.hpp"
#include "cnccomp/identification/rtest_axis_tables.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "cnccomp/io/plan_xml.hpp"

namespace cnccomp {
using namespace cnccomp::identification;
using namespace cnccomp::io;
using namespace cnccomp::measurement;
namespace {

std::string sample(const std::string& rel) { return std::string(CNCCOMP_SOURCE_DIR) + "/samples/" + rel; }

struct TableTable {
    MachineModel machine = readMachineXml(sample("machines/table-table-ac.xml"));
    MeasurementPlan rtest = readPlanXml(sample("plans/table-table-ac-rtest.xml"));
    MeasurementPlan kinematic = readPlanXml(sample("plans/table-table-ac-kinematic.xml"));
    MeasurementPlan dbb5 = readPlanXml(sample("plans/dbb5-table-table-ac.xml"));
    std::vector<RtestTrace> rtestTraces, kinematicTraces;
    std::vector<BallbarTrace> dbb5Traces;
    TableTable() {
        const Kinematics k1(machine, readDeviationCsv(sample("deviations/table-table-ac-truth.csv"), machine));
        for (const RtestRun& r : rtest.rtestRuns) rtestTraces.push_back(simulateRtest(k1, r));
        const Kinematics k4(machine, readDeviationCsv(sample("deviations/table-table-ac-kinematic.csv"), machine));
        for (const RtestRun& r : kinematic.rtestRuns) kinematicTraces.push_back(simulateRtest(k4, r));
        const Kinematics k3(machine, readDeviationCsv(sample("deviations/dbb5-truth.csv"), machine));
        for (const Dbb5Run& r : dbb5.dbb5Runs) dbb5Traces.push_back(simulateDbb5(k3, r));
    }
};

TableTable& tableTable() {
    static TableTable f;
    return f;
}

struct Head {
    MachineModel machine = readMachineXml(sample("machines/tilting-head-b.xml"));
    MeasurementPlan plan = readPlanXml(sample("plans/tilting-head-b-patterns.xml"));
    std::vector<BallbarTrace> traces;
    Head() {
        const Kinematics k(machine, readDeviationCsv(sample("deviations/tilting-head-b-truth.csv"), machine));
        for (const BallbarRun& r : plan.absoluteRuns) traces.push_back(simulateAbsoluteRun(k, r));
    }
};

Head& head() {
    static Head f;
    return f;
}

void BM_RtestLocationFitsRefined(benchmark::State& state) {
    TableTable& f = tableTable();
    for (auto _ : state) benchmark::DoNotOptimize(rtestLocationFits(f.machine, f.rtest.rtestRuns, f.rtestTraces));
}
BENCHMARK(BM_RtestLocationFitsRefined)->Unit(benchmark::kMillisecond);

void BM_HeadPatternFormulas(benchmark::State& state) {
    Head& f = head();
    for (auto _ : state) benchmark::DoNotOptimize(tiltingHeadFormulas(f.plan.absoluteRuns, f.traces));
}
BENCHMARK(BM_HeadPatternFormulas)->Unit(benchmark::kMicrosecond);

void BM_HeadPatternLeastSquares(benchmark::State& state) {
    Head& f = head();
    for (auto _ : state) benchmark::DoNotOptimize(tiltingHeadLeastSquares(f.machine, f.plan.absoluteRuns, f.traces));
}
BENCHMARK(BM_HeadPatternLeastSquares)->Unit(benchmark::kMillisecond);

void BM_Dbb5LocationErrorsRefined(benchmark::State& state) {
    TableTable& f = tableTable();
    for (auto _ : state) benchmark::DoNotOptimize(dbb5LocationErrors(f.machine, f.dbb5.dbb5Runs, f.dbb5Traces));
}
BENCHMARK(BM_Dbb5LocationErrorsRefined)->Unit(benchmark::kMillisecond);

void BM_RtestTablesPerAngle(benchmark::State& state) {
    TableTable& f = tableTable();
    for (auto _ : state)
        benchmark::DoNotOptimize(cradleTablesPerAngle(f.machine, "A", "C", f.kinematic.rtestRuns, f.kinematicTraces));
}
BENCHMARK(BM_RtestTablesPerAngle)->Unit(benchmark::kMicrosecond);

void BM_RtestTablesLeastSquares(benchmark::State& state) {
    TableTable& f = tableTable();
    for (auto _ : state)
        benchmark::DoNotOptimize(cradleLeastSquares(f.machine, "A", "C", f.kinematic.rtestRuns, f.kinematicTraces));
}
BENCHMARK(BM_RtestTablesLeastSquares)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace cnccomp
