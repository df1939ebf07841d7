// Least-squares identification of the 12 [MultiTasking] deviations from the six ball-bar runs of section 5.3, on the exact
// model: each run a 360-sample trace (1° steps, the main job's; argument 360) or a 3600-sample one (0.1°). CPU time.
#include <benchmark/benchmark.h>

#include <filesystem>

#include "app/identify.hpp"
#include "cnccomp/io/trace_csv.hpp"

#include "cnccomp/identification/lsq.hpp"
#include "cnccomp/identification/parameters.hpp"
#include "cnccomp/identification/problem.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "cnccomp/io/plan_xml.hpp"

namespace cnccomp {
using namespace cnccomp::identification;
using namespace cnccomp::io;
using namespace cnccomp::measurement;
namespace {

struct Fixture {
    MachineModel machine = readMachineXml(std::string(CNCCOMP_SOURCE_DIR) + "/samples/machines/multitasking.xml");
    DeviationSet truth = readDeviationCsv(std::string(CNCCOMP_SOURCE_DIR) + "/samples/deviations/multitasking-truth.csv", machine);
    std::vector<BallbarRun> runs = readPlanXml(std::string(CNCCOMP_SOURCE_DIR) + "/samples/plans/multitasking-six-circles.xml").runs;
    std::vector<BallbarTrace> traces;
    IdentifyOptions options;
    explicit Fixture(int samples) {
        const Kinematics k(machine, truth);
        for (BallbarRun& r : runs) {
            r.stepDeg = 360.0 / samples;
            traces.push_back(simulateRun(k, r));
        }
        options.deviations = parseDeviationList(machine, "dxBT dzBT aBT aXB bXB gXB aYZ bYZ dxCZ dyCZ aCZ bCZ");
        DeviationSet start = truth;  // γXY known, the twelve start from zero
        for (int i : options.deviations) start.values[machine.deviations[i].offset] = 0.0;
        options.start = start;
    }
};

Fixture& fixture(int samples = 3600) {
    static Fixture f360(360), f3600(3600);
    return samples == 360 ? f360 : f3600;
}

void BM_IdentifyTwelveFromSixTraces(benchmark::State& state) {
    Fixture& f = fixture(static_cast<int>(state.range(0)));
    const Observations obs = ballbarObservations(f.machine, f.runs, f.traces);
    int iterations = 0;
    for (auto _ : state) {
        const IdentificationResult r = identify(f.machine, obs, f.options);
        iterations = r.report.iterations;
        benchmark::DoNotOptimize(r.deviations.values.data());
    }
    state.counters["samples"] = static_cast<double>(obs.size() * f.traces[0].dL.size());
    state.counters["lm_iterations"] = iterations;
}
BENCHMARK(BM_IdentifyTwelveFromSixTraces)->ArgName("samples")->Arg(360)->Arg(3600)->Unit(benchmark::kMillisecond);

void BM_JacobianSixTraces(benchmark::State& state) {
    Fixture& f = fixture();
    const Observations obs = ballbarObservations(f.machine, f.runs, f.traces);
    const UnknownLayout layout(f.machine, f.options.deviations, obs);
    const LsqProblem p(f.machine, obs, layout, *f.options.start);
    Eigen::MatrixXd J;
    for (auto _ : state) {
        p.jacobian(p.start(), J);
        benchmark::DoNotOptimize(J.data());
    }
}
BENCHMARK(BM_JacobianSixTraces)->Unit(benchmark::kMillisecond);

void BM_ResidualsSixTraces(benchmark::State& state) {
    Fixture& f = fixture();
    const Observations obs = ballbarObservations(f.machine, f.runs, f.traces);
    const UnknownLayout layout(f.machine, f.options.deviations, obs);
    const LsqProblem p(f.machine, obs, layout, *f.options.start);
    Eigen::VectorXd r;
    for (auto _ : state) {
        p.residuals(p.start(), r);
        benchmark::DoNotOptimize(r.data());
    }
}
BENCHMARK(BM_ResidualsSixTraces)->Unit(benchmark::kMillisecond);


// The same main job through the identification façade (src/app/identify.hpp), as `cnccomp identify` runs it: the
// options checked, the method looked up, the six instrument files read once (360 samples each), least squares, the
// summary. CPU time; the files are written once to a temporary folder.
void BM_FacadeIdentifyMainJob(benchmark::State& state) {
    Fixture& f = fixture(360);
    const std::filesystem::path dir = std::filesystem::temp_directory_path() / "cnccomp-bench-facade";
    std::filesystem::create_directories(dir);
    MeasurementPlan plan;
    plan.runs = f.runs;
    for (size_t i = 0; i < f.runs.size(); ++i)
        writeTraceCsv((dir / (f.runs[i].name + ".csv")).string(), f.traces[i], f.runs[i], f.machine.name);
    writeDeviationCsv((dir / "start.csv").string(), *f.options.start, true);
    app::IdentificationOptions o;
    o.traces = dir.string();
    o.params = "dxBT dzBT aBT aXB bXB gXB aYZ bYZ dxCZ dyCZ aCZ bCZ";
    o.start = (dir / "start.csv").string();
    int iterations = 0;
    for (auto _ : state) {
        const app::IdentificationSummary s = app::identify(f.machine, &plan, o);
        iterations = s.report->iterations;
        benchmark::DoNotOptimize(s.deviations.values.data());
    }
    state.counters["lm_iterations"] = iterations;
    std::filesystem::remove_all(dir);
}
BENCHMARK(BM_FacadeIdentifyMainJob)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime();

}  // namespace
}  // namespace cnccomp
