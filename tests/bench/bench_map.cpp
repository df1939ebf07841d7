// Volumetric map throughput on the multitasking machine:
//  - evaluation, poses/s: a 1 M-point grid, statistics only (all cores, 1 and 2 threads), with the points kept, and a
//    fixed-orientation grid (inverse kinematics per point);
//  - the CSV rows, rows/s: formatting alone on one thread, the formatter against fmt's "{:.6f}" / "{:.5f}" (what the
//    writer used before; same text), and the whole streamed file (statistics pass + evaluation + formatting + writing,
//    1 and 2 threads) to a temporary file.
// Real time (items/s is poses/s or rows/s of real time) and the CPU time of the whole process (all threads): on a
// machine shared with other work, points / CPU time is the per-core figure.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <filesystem>
#include <iterator>
#include <string>

#include <fmt/format.h>

#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "cnccomp/io/map_csv.hpp"
#include "cnccomp/volumetric_map.hpp"

namespace {

using namespace cnccomp;
using namespace cnccomp::io;

struct Fixture {
    MachineModel m = readMachineXml(std::string(CNCCOMP_SOURCE_DIR) + "/samples/machines/multitasking.xml");
    DeviationSet d = readDeviationCsv(std::string(CNCCOMP_SOURCE_DIR) + "/samples/deviations/multitasking-truth.csv", m);
};
const Fixture& fixture() {
    static const Fixture f;
    return f;
}

// 101 × 101 × 10 × 10 = 1 020 100 poses.
constexpr const char* kMillion = "X=-200:200:4 Y=-200:200:4 B=-90:90:20 C=0:324:36";

void BM_MapStatistics1M(benchmark::State& state) {
    const Fixture& f = fixture();
    MapRequest r{f.m, f.d, parseGrid(kMillion), 100.0, std::nullopt, static_cast<int>(state.range(0))};
    for (auto _ : state) benchmark::DoNotOptimize(mapStatistics(r).norm.maxAbs);
    state.SetItemsProcessed(state.iterations() * r.grid.size());
}
BENCHMARK(BM_MapStatistics1M)->ArgName("threads")->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->UseRealTime();

void BM_ComputeMap1M(benchmark::State& state) {
    const Fixture& f = fixture();
    MapRequest r{f.m, f.d, parseGrid(kMillion), 100.0, std::nullopt, 0};
    for (auto _ : state) benchmark::DoNotOptimize(computeMap(r).stats.norm.maxAbs);
    state.SetItemsProcessed(state.iterations() * r.grid.size());
}
BENCHMARK(BM_ComputeMap1M)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->UseRealTime();

void BM_MapFixedOrientation(benchmark::State& state) {
    const Fixture& f = fixture();
    MapRequest r{f.m, f.d, parseGrid("X=-200:200:4 Y=-200:200:4 Z=0:90:10"), 100.0, Vec3(0.5, 0, -0.8660254037844386), 0};
    for (auto _ : state) benchmark::DoNotOptimize(mapStatistics(r).norm.maxAbs);
    state.SetItemsProcessed(state.iterations() * r.grid.size());
}
BENCHMARK(BM_MapFixedOrientation)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->UseRealTime();

/// 100 000 points of the million grid (its first X values), computed once.
const VolumetricMap& rowsMap() {
    static const VolumetricMap map = [] {
        const Fixture& f = fixture();
        return computeMap(MapRequest{f.m, f.d, parseGrid("X=-200:-164:4 Y=-200:200:4 B=-90:90:20 C=0:324:36"), 100.0, std::nullopt, 0});
    }();
    return map;
}

void BM_MapCsvRowsFormat(benchmark::State& state) {
    const Fixture& f = fixture();
    const VolumetricMap& map = rowsMap();
    std::string text;  // reused, as the streamed writer reuses its block buffers
    for (auto _ : state) {
        text.clear();
        appendMapRows(map.points, f.m, text);
        benchmark::DoNotOptimize(text.data());
    }
    state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(map.points.size()));
    state.SetBytesProcessed(state.iterations() * static_cast<int64_t>(text.size()));
}
BENCHMARK(BM_MapCsvRowsFormat)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->UseRealTime();

/// The same rows written by fmt as the map writer did before (the yardstick; the text is the same).
void BM_MapCsvRowsFormatFmt(benchmark::State& state) {
    const Fixture& f = fixture();
    const VolumetricMap& map = rowsMap();
    const MachineModel& m = f.m;
    std::array<double, kMaxAxes> scale{};
    for (int a = 0; a < m.axisCount(); ++a) scale[a] = m.axisLink(a).kind == AxisKind::Rotary ? 1.0 / kDeg : 1.0;
    std::string out;  // reused
    for (auto _ : state) {
        out.clear();
        for (const MapPoint& p : map.points) {
            for (int a = 0; a < m.axisCount(); ++a) fmt::format_to(std::back_inserter(out), "{:.6f},", p.q[a] * scale[a]);
            fmt::format_to(std::back_inserter(out), "{:.6f},{:.6f},{:.6f},{:.5f},{:.5f},{:.5f},{:.5f},{:.5f},{:.5f},{:.5f},{:.5f},{}\n",
                           p.tip.x(), p.tip.y(), p.tip.z(), p.error.x() / kUm, p.error.y() / kUm, p.error.z() / kUm,
                           p.error.norm() / kUm, p.rotation.x() / kArcsec, p.rotation.y() / kArcsec,
                           p.rotation.z() / kArcsec, p.tilt / kArcsec, p.ok ? 1 : 0);
        }
        benchmark::DoNotOptimize(out.data());
    }
    state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(map.points.size()));
}
BENCHMARK(BM_MapCsvRowsFormatFmt)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->UseRealTime();

/// The whole streamed file of the million grid (what `cnccomp map` does), to a temporary file removed at the end.
void BM_MapCsvStreamed1M(benchmark::State& state) {
    const Fixture& f = fixture();
    MapRequest r{f.m, f.d, parseGrid(kMillion), 100.0, std::nullopt, static_cast<int>(state.range(0))};
    const std::string path =
        (std::filesystem::temp_directory_path() / ("cnccomp-bench-map-" + std::to_string(::getpid()) + ".csv")).string();
    for (auto _ : state) benchmark::DoNotOptimize(streamMapCsv(path, r, {f.m.name, "truth.csv"}).points);
    state.counters["MB"] = static_cast<double>(std::filesystem::file_size(path)) / 1e6;
    std::error_code ec;
    std::filesystem::remove(path, ec);
    state.SetItemsProcessed(state.iterations() * r.grid.size());
}
BENCHMARK(BM_MapCsvStreamed1M)->ArgName("threads")->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->UseRealTime();

}  // namespace
