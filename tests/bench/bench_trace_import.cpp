// Import of a measured ball-bar trace: a file at the plan's step (360 samples) and a densely sampled one (1 kHz class:
// 1 000 000 samples over the same turn, averaged into the plan's 1° bins), as bytes read a second. Compare the two
// (`farm-bench --vs`, or the counters of one run): the dense file should read at the same bytes/s as the plan-step
// file (a 38 MB file took 81 s and 1.24 GB in identify; now about 1.7 s and 130 MB end to end).
#include <benchmark/benchmark.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>

#include "cnccomp/io/plan_xml.hpp"
#include "cnccomp/io/trace_import.hpp"

namespace cnccomp {
using namespace cnccomp::io;
using namespace cnccomp::measurement;
namespace {

struct TraceFile {
    std::string path;
    double bytes = 0;
};

/// One angle-sampled pass of run B-X (-180..180°) with `n` samples, a smooth made-up ΔL; written once per size.
TraceFile writeTrace(int n) {
    TraceFile f;
    f.path = (std::filesystem::temp_directory_path() / fmt::format("cnccomp-bench-trace-{}.csv", n)).string();
    std::ofstream o(f.path);
    o << "angle_deg,dL_um\n";
    for (int i = 0; i < n; ++i) {
        const double a = -180.0 + 359.0 * i / (n - 1);
        o << fmt::format("{:.6f},{:.6f}\n", a, 3.0 * std::sin(2 * a * M_PI / 180) + 0.5 * std::cos(a * M_PI / 180));
    }
    o.close();
    f.bytes = static_cast<double>(std::filesystem::file_size(f.path));
    return f;
}

const BallbarRun& runBX() {
    static const MeasurementPlan plan =
        readPlanXml(std::string(CNCCOMP_SOURCE_DIR) + "/samples/plans/multitasking-six-circles.xml");
    return plan.runs.front();
}

void BM_ImportTrace(benchmark::State& state) {
    static std::map<int, TraceFile> files;
    const int n = static_cast<int>(state.range(0));
    if (!files.count(n)) files[n] = writeTrace(n);
    const TraceFile& f = files[n];
    size_t kept = 0;
    for (auto _ : state) {
        const MeasuredTrace t = importRunTrace(f.path, runBX());
        kept = t.trace.dL.size();
        benchmark::DoNotOptimize(kept);
    }
    state.counters["bytes/s"] = benchmark::Counter(f.bytes, benchmark::Counter::kIsIterationInvariantRate);
    state.counters["kept"] = static_cast<double>(kept);
}
BENCHMARK(BM_ImportTrace)->Arg(360)->Arg(1000000)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace cnccomp
