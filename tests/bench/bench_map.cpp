// Volumetric map throughput: poses per second on a 1 M-point grid (all cores), statistics only and with the
// points kept; and one-thread throughput on a smaller grid.
#include <benchmark/benchmark.h>

#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "cnccomp/volumetric_map.hpp"

namespace {

using namespace cnccomp;

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
BENCHMARK(BM_MapStatistics1M)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_ComputeMap1M(benchmark::State& state) {
    const Fixture& f = fixture();
    MapRequest r{f.m, f.d, parseGrid(kMillion), 100.0, std::nullopt, 0};
    for (auto _ : state) benchmark::DoNotOptimize(computeMap(r).stats.norm.maxAbs);
    state.SetItemsProcessed(state.iterations() * r.grid.size());
}
BENCHMARK(BM_ComputeMap1M)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_MapFixedOrientation(benchmark::State& state) {
    const Fixture& f = fixture();
    MapRequest r{f.m, f.d, parseGrid("X=-200:200:4 Y=-200:200:4 Z=0:90:10"), 100.0, Vec3(0.5, 0, -0.8660254037844386), 0};
    for (auto _ : state) benchmark::DoNotOptimize(mapStatistics(r).norm.maxAbs);
    state.SetItemsProcessed(state.iterations() * r.grid.size());
}
BENCHMARK(BM_MapFixedOrientation)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
