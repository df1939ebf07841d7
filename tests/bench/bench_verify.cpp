// `cnccomp verify` of the six-run plan ([MultiTasking], 1° steps: 2 × 2160 samples) through the files of each backend on the
// multi-tasking machine: test programs generated and read back, the apply model on every command, ΔL, ISO 230-4 figures,
// and the volumetric grid (5 per axis, two tool lengths: 6250 poses). Target: < 1 s each.
#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "app/verify.hpp"
#include "controllers/backend.hpp"

namespace {

using namespace cnccomp;
using namespace cnccomp::io;
using namespace cnccomp::measurement;

void BM_VerifySixRunPlan(benchmark::State& state, const std::string& backendName) {
    const std::string dir = CNCCOMP_SOURCE_DIR;
    const MachineModel m = readMachineXml(dir + "/samples/machines/multitasking.xml");
    const MeasurementPlan plan = readPlanXml(dir + "/samples/plans/multitasking-six-circles.xml");
    const DeviationSet truth = readDeviationCsv(dir + "/samples/deviations/multitasking-truth.csv", m);
    app::VerifyCompensation comp;
    if (backendName == "ideal") {
        comp.kind = app::VerifyCompensation::Kind::Deviations;
        comp.model = app::idealCompensation(m, truth);
    } else {
        const controllers::Backend& b = controllers::backend(backendName);
        const controllers::EmitResult files = b.emit({m, truth, "truth.csv", "2024-01-01"});
        comp.kind = app::VerifyCompensation::Kind::ControllerFiles;
        comp.model = std::shared_ptr<const controllers::AppliedCompensation>(b.apply(m, files.files));
        comp.notCompensated = files.notCompensated;
    }
    const app::VerifyResult once = app::verify(m, plan, truth, "truth", comp);
    state.SetLabel(fmt::format("residual {:.3f} um (before {:.3f})", once.residual / kUm, once.residualBefore / kUm));
    for (auto _ : state) {
        const app::VerifyResult r = app::verify(m, plan, truth, "truth", comp);
        benchmark::DoNotOptimize(r.residual);
    }
}

BENCHMARK_CAPTURE(BM_VerifySixRunPlan, ideal, std::string("ideal"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_VerifySixRunPlan, fanuc, std::string("fanuc-30i"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_VerifySixRunPlan, generic, std::string("generic"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_VerifySixRunPlan, heidenhain, std::string("heidenhain-tnc"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_VerifySixRunPlan, isg, std::string("isg"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_VerifySixRunPlan, linuxcnc, std::string("linuxcnc"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_VerifySixRunPlan, siemens, std::string("siemens-840d"))->Unit(benchmark::kMillisecond);

}  // namespace
