// The other papers' methods on their sample plans (noise-free data): seed 001 R-test fits with refinement, seed 002
// tilting-head formulas and least squares, seed 003 DBB5 formulas, seed 004 per-angle and least-squares tables.
#include <benchmark/benchmark.h>

#include "cnccomp/identification/seed001_rtest.hpp"
#include "cnccomp/identification/seed002_tilting_head.hpp"
#include "cnccomp/identification/dbb5_location_errors.hpp"
#include "cnccomp/identification/seed004_cradle.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "cnccomp/io/plan_xml.hpp"

namespace cnccomp {
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
    MeasurementPlan plan = readPlanXml(sample("plans/tilting-head-b-seed002.xml"));
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

void BM_Seed001RtestFitsRefined(benchmark::State& state) {
    TableTable& f = tableTable();
    for (auto _ : state) benchmark::DoNotOptimize(seed001Formulas(f.machine, f.rtest.rtestRuns, f.rtestTraces));
}
BENCHMARK(BM_Seed001RtestFitsRefined)->Unit(benchmark::kMillisecond);

void BM_Seed002Formulas(benchmark::State& state) {
    Head& f = head();
    for (auto _ : state) benchmark::DoNotOptimize(tiltingHeadFormulas(f.plan.absoluteRuns, f.traces));
}
BENCHMARK(BM_Seed002Formulas)->Unit(benchmark::kMicrosecond);

void BM_Seed002LeastSquares(benchmark::State& state) {
    Head& f = head();
    for (auto _ : state) benchmark::DoNotOptimize(tiltingHeadLeastSquares(f.machine, f.plan.absoluteRuns, f.traces));
}
BENCHMARK(BM_Seed002LeastSquares)->Unit(benchmark::kMillisecond);

void BM_Dbb5LocationErrorsRefined(benchmark::State& state) {
    TableTable& f = tableTable();
    for (auto _ : state) benchmark::DoNotOptimize(dbb5LocationErrors(f.machine, f.dbb5.dbb5Runs, f.dbb5Traces));
}
BENCHMARK(BM_Dbb5LocationErrorsRefined)->Unit(benchmark::kMillisecond);

void BM_Seed004PerAngle(benchmark::State& state) {
    TableTable& f = tableTable();
    for (auto _ : state)
        benchmark::DoNotOptimize(seed004Formulas(f.machine, "A", "C", f.kinematic.rtestRuns, f.kinematicTraces));
}
BENCHMARK(BM_Seed004PerAngle)->Unit(benchmark::kMicrosecond);

void BM_Seed004LeastSquares(benchmark::State& state) {
    TableTable& f = tableTable();
    for (auto _ : state)
        benchmark::DoNotOptimize(cradleLeastSquares(f.machine, "A", "C", f.kinematic.rtestRuns, f.kinematicTraces));
}
BENCHMARK(BM_Seed004LeastSquares)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace cnccomp
