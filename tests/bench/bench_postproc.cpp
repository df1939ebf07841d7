// Post-processor throughput on programs of >= 1 M lines (written once to a temporary file and streamed from it):
//  - a generated 5-axis program on the multitasking machine (joint mode): identity and correction;
//  - the real impeller of LinuxCNC's xyzac-trt sim (../shared/gcode-corpus/impeller-7bl-xyzac.ngc, its body repeated
//    to >= 1 M lines after M428): identity and correction in TCP mode on the sim's machine (skipped without the
//    corpus), on one and on two threads (--threads; the argument), in wall-clock time; and the two in turn, pair by
//    pair (BM_PostprocImpellerPairs): the median of the pairs' ratios identity time / correction time is the issue's
//    throughput figure (correction throughput / identity throughput).
// Reports lines/s and bytes/s (CPU time of the calling thread, real time for the impeller); memory use does not depend
// on the program size (fixed read and write buffers; the output goes to a counting sink).
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <streambuf>
#include <string>
#include <vector>

#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "postproc/correct_program.hpp"
#include "tests/test_postproc_xyzac.hpp"

namespace {

using namespace cnccomp;
using namespace cnccomp::io;

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

/// Corrects the program at `path` once into a counting sink.
postproc::CorrectSummary correctOnce(const MachineModel& m, const DeviationSet& d, const std::string& path,
                                     const postproc::CorrectOptions& o) {
    std::ifstream in(path, std::ios::binary);
    CountingBuf sink;
    std::ostream out(&sink);
    const postproc::CorrectSummary s = postproc::correctProgram(m, d, in, out, o);
    benchmark::DoNotOptimize(sink.bytes);
    return s;
}

/// Corrects the program at `path` once per iteration into a counting sink; lines/s, bytes/s and what was done.
void measure(benchmark::State& state, const MachineModel& m, const DeviationSet& d, const std::string& path,
             const postproc::CorrectOptions& o) {
    const auto bytes = std::filesystem::file_size(path);
    postproc::CorrectSummary s;
    for (auto _ : state) s = correctOnce(m, d, path, o);
    state.counters["lines/s"] = benchmark::Counter(double(s.lines) * state.iterations(), benchmark::Counter::kIsRate);
    state.counters["lines"] = double(s.lines);
    state.counters["split"] = double(s.split);
    state.counters["corrected"] = double(s.corrected);
    state.counters["tcp moves"] = double(s.tcpMoves);
    state.SetBytesProcessed(static_cast<int64_t>(bytes) * state.iterations());
}

void run(benchmark::State& state, bool identity) {
    static const MachineModel m = readMachineXml(std::string(CNCCOMP_SOURCE_DIR) + "/samples/machines/multitasking.xml");
    static const DeviationSet truth =
        readDeviationCsv(std::string(CNCCOMP_SOURCE_DIR) + "/samples/deviations/multitasking-truth.csv", m);
    const DeviationSet zero(m);
    postproc::CorrectOptions o;
    o.dialect = postproc::Dialect::Rs274ngc;
    o.setup.addToolLength("100");
    measure(state, m, identity ? zero : truth, programPath(), o);
}

void BM_PostprocIdentity(benchmark::State& state) { run(state, true); }
void BM_PostprocCorrect5Axis(benchmark::State& state) { run(state, false); }

BENCHMARK(BM_PostprocIdentity)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_PostprocCorrect5Axis)->Unit(benchmark::kMillisecond)->Iterations(2);

// --- The real 5-axis program: LinuxCNC's impeller demo in TCP mode ---------------------------------------------------

struct Impeller {
    std::string program, machine, deviations;
    bool ok = false;
    ~Impeller() {
        std::error_code ec;
        for (const auto& p : {program, machine, deviations})
            if (!p.empty()) std::filesystem::remove(p, ec);
    }
};

const Impeller& impeller() {
    static Impeller im;
    static const bool once = [] {
        const std::string src = std::string(CNCCOMP_SOURCE_DIR) + "/../shared/gcode-corpus/impeller-7bl-xyzac.ngc";
        std::ifstream in(src, std::ios::binary);
        if (!in) return false;
        std::vector<std::string> body;
        bool inside = false;
        for (std::string l; std::getline(in, l);) {
            if (l.rfind("M428", 0) == 0) {
                inside = true;
                continue;
            }
            if (l.rfind("M429", 0) == 0) inside = false;
            if (inside) body.push_back(l);
        }
        const auto tmp = std::filesystem::temp_directory_path();
        const std::string tag = std::to_string(::getpid());
        im.program = (tmp / ("cnccomp-bench-impeller-" + tag + ".ngc")).string();
        im.machine = (tmp / ("cnccomp-bench-xyzac-" + tag + ".xml")).string();
        im.deviations = (tmp / ("cnccomp-bench-xyzac-" + tag + ".csv")).string();
        std::ofstream(im.machine) << test::kXyzacTrtMachine;
        std::ofstream(im.deviations) << "name,alias,value,unit\nEY0A,,8,um\nEZ0A,,-12,um\nEA0A,,12,arcsec\nEB0A,,10,arcsec\n"
                                        "EC0A,,-6,arcsec\nEX0C,,15,um\nEY0C,,-9,um\nEA0C,,7,arcsec\nEB0C,,-5,arcsec\n"
                                        "EC0Y,,4,arcsec\n";
        std::ofstream out(im.program, std::ios::binary);
        out << "(impeller body of LinuxCNC's xyzac-trt demo, repeated)\nM428\n";
        size_t lines = 2;
        while (lines < size_t(kLines)) {
            for (const std::string& l : body) out << l << '\n';
            lines += body.size();
        }
        out << "M429\nM30\n";
        return true;
    }();
    im.ok = once;
    return im;
}

/// The impeller's machine, its deviation set and the options of the TCP correction (null when the corpus is missing).
struct ImpellerJob {
    const MachineModel* machine = nullptr;
    const DeviationSet* truth = nullptr;
    postproc::CorrectOptions options;
};

bool impellerJob(benchmark::State& state, ImpellerJob& job) {
    const Impeller& im = impeller();
    if (!im.ok) {
        state.SkipWithError("no ../shared/gcode-corpus/impeller-7bl-xyzac.ngc");
        return false;
    }
    static const MachineModel m = readMachineXml(im.machine);
    static const DeviationSet truth = readDeviationCsv(im.deviations, m);
    job.machine = &m;
    job.truth = &truth;
    job.options.dialect = postproc::Dialect::Rs274ngc;
    job.options.setup.addToolLength("30");
    job.options.tcpOnM = 428;
    job.options.tcpOffM = 429;
    job.options.threads = static_cast<int>(state.range(0));
    return true;
}

void runImpeller(benchmark::State& state, bool identity) {
    ImpellerJob job;
    if (!impellerJob(state, job)) return;
    const DeviationSet zero(*job.machine);
    measure(state, *job.machine, identity ? zero : *job.truth, impeller().program, job.options);
}

void BM_PostprocImpellerIdentity(benchmark::State& state) { runImpeller(state, true); }
void BM_PostprocImpellerCorrectTcp(benchmark::State& state) { runImpeller(state, false); }

BENCHMARK(BM_PostprocImpellerIdentity)->ArgName("threads")->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_PostprocImpellerCorrectTcp)->ArgName("threads")->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond)->Iterations(3);

/// The throughput figure on a machine whose speed drifts: identity and correction in turn, one pair per
/// iteration (the order alternating from pair to pair), each pair's ratio identity time / correction time (=
/// correction throughput / identity throughput), and the median of the pairs' ratios with their spread. Two runs far
/// apart in time (as the two benchmarks above) can differ by 40 % on a shared host; the two halves of a pair cannot
/// drift apart by much. Wall-clock time of the whole correction (both threads' work on two).
void BM_PostprocImpellerPairs(benchmark::State& state) {
    ImpellerJob job;
    if (!impellerJob(state, job)) return;
    const DeviationSet zero(*job.machine);
    const std::string& path = impeller().program;
    auto seconds = [&](const DeviationSet& d) {
        const auto t0 = std::chrono::steady_clock::now();
        correctOnce(*job.machine, d, path, job.options);
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    };
    std::vector<double> ratios, identity, correction;
    for (auto _ : state) {
        double ti, tc;
        if (ratios.size() % 2 == 0) ti = seconds(zero), tc = seconds(*job.truth);
        else tc = seconds(*job.truth), ti = seconds(zero);
        identity.push_back(ti);
        correction.push_back(tc);
        ratios.push_back(ti / tc);
    }
    auto median = [](std::vector<double> v) {
        std::sort(v.begin(), v.end());
        const size_t n = v.size();
        return n == 0 ? 0.0 : n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
    };
    state.counters["ratio median"] = median(ratios);
    state.counters["ratio min"] = ratios.empty() ? 0.0 : *std::min_element(ratios.begin(), ratios.end());
    state.counters["ratio max"] = ratios.empty() ? 0.0 : *std::max_element(ratios.begin(), ratios.end());
    // Two estimates that lean less on any single pair on a host whose speed drifts by tens of percent within seconds:
    // the ratio of the summed times (drift shared by both over the run) and of the fastest times (each job's least
    // disturbed run).
    double sumI = 0, sumC = 0;
    for (size_t k = 0; k < ratios.size(); ++k) sumI += identity[k], sumC += correction[k];
    state.counters["ratio of sums"] = sumC > 0 ? sumI / sumC : 0.0;
    state.counters["ratio of minima"] = ratios.empty() ? 0.0
                                                       : *std::min_element(identity.begin(), identity.end()) /
                                                             *std::min_element(correction.begin(), correction.end());
    state.counters["identity ms"] = 1e3 * median(identity);
    state.counters["correction ms"] = 1e3 * median(correction);
    state.counters["pairs"] = double(ratios.size());
}

BENCHMARK(BM_PostprocImpellerPairs)->ArgName("threads")->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond)->Iterations(15);

}  // namespace
