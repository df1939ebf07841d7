// Post-processor throughput on a generated program of >= 1 M lines (written once to a temporary file and
// streamed from it): identity (all-zero deviation set) and 5-axis correction with simultaneous rotary motion
// on the multitasking machine. Reports lines/s and bytes/s; memory use does not depend on the program size
// (fixed read and write buffers; the output goes to a counting sink).
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <streambuf>
#include <string>

#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "postproc/processor.hpp"

namespace {

using namespace cnccomp;

constexpr int kLines = 1'000'000;

/// A 5-axis finishing program: small steps along a tilted contour with B and C moving on every block
/// (4 decimals in mm, 3 in degrees), as CAM output for the multitasking machine looks.
/// The generated program lives in the system temp folder for the run and is removed at exit.
struct TempProgram {
    std::string path;
    ~TempProgram() {
        std::error_code ec;
        if (!path.empty()) std::filesystem::remove(path, ec);
    }
};

const std::string& programPath() {
    static TempProgram program;
    static const std::string path = [] {
        const std::string p =
            (std::filesystem::temp_directory_path() / ("cnccomp-bench-5axis-" + std::to_string(::getpid()) + ".ngc")).string();
        std::FILE* f = std::fopen(p.c_str(), "wb");
        if (!f) return p;
        std::fprintf(f, "(benchmark program: %d lines)\nG21 G90 G17 G94\nG0 X50.0000 Y0.0000 Z40.0000 B0.000 C0.000\nG1 Z12.0000 F800.\n", kLines);
        for (int k = 4; k < kLines; ++k) {
            const double c = 0.05 * k;
            const double r = c * kDeg;
            std::fprintf(f, "X%.4f Y%.4f Z%.4f B%.3f C%.3f\n", 45.0 + 5.0 * std::cos(3 * r), 2.0 * std::sin(r),
                         10.0 + 2.0 * std::sin(2 * r), 20.0 + 10.0 * std::sin(2 * r), std::fmod(c, 3600.0));
        }
        std::fclose(f);
        program.path = p;
        return p;
    }();
    return path;
}

/// Counts bytes, keeps nothing: the output's memory must not grow with the program.
class CountingBuf : public std::streambuf {
public:
    std::streamsize bytes = 0;

protected:
    std::streamsize xsputn(const char*, std::streamsize n) override {
        bytes += n;
        return n;
    }
    int_type overflow(int_type c) override {
        ++bytes;
        return c;
    }
};

void run(benchmark::State& state, bool identity) {
    static const MachineModel m = readMachineXml(std::string(CNCCOMP_SOURCE_DIR) + "/samples/machines/multitasking.xml");
    static const DeviationSet truth =
        readDeviationCsv(std::string(CNCCOMP_SOURCE_DIR) + "/samples/deviations/multitasking-truth.csv", m);
    const DeviationSet zero(m);
    const std::string& path = programPath();
    const auto bytes = std::filesystem::file_size(path);
    pp::CorrectOptions o;
    o.dialect = pp::Dialect::Rs274ngc;
    o.setup.addToolLength("100");
    pp::CorrectSummary s;
    for (auto _ : state) {
        std::ifstream in(path, std::ios::binary);
        CountingBuf sink;
        std::ostream out(&sink);
        s = pp::correctProgram(m, identity ? zero : truth, in, out, o);
        benchmark::DoNotOptimize(sink.bytes);
    }
    state.counters["lines/s"] = benchmark::Counter(double(s.lines) * state.iterations(), benchmark::Counter::kIsRate);
    state.counters["lines"] = double(s.lines);
    state.counters["split"] = double(s.split);
    state.counters["corrected"] = double(s.corrected);
    state.SetBytesProcessed(static_cast<int64_t>(bytes) * state.iterations());
}

void BM_PostprocIdentity(benchmark::State& state) { run(state, true); }
void BM_PostprocCorrect5Axis(benchmark::State& state) { run(state, false); }

BENCHMARK(BM_PostprocIdentity)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_PostprocCorrect5Axis)->Unit(benchmark::kMillisecond)->Iterations(2);

}  // namespace
