// Measured traces in the wrong unit: an mm export under a dL_um header, or µm data under
// length-unit="mm", is refused naming the likely unit; a large file streams.
#include <chrono>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "cnccomp/units.hpp"
#include "cnccomp/io/trace_import.hpp"
#include "test_support.hpp"

namespace cnccomp {
using namespace cnccomp::io;
using namespace cnccomp::measurement;
namespace {

namespace fs = std::filesystem;

const std::string kMachine = test::sourcePath("samples/machines/multitasking.xml");
const std::string kPlan = test::sourcePath("samples/plans/multitasking-six-circles.xml");
const std::string kTruth = test::sourcePath("samples/deviations/multitasking-truth.csv");

std::string simulateInto(const test::ScratchDir& dir) {
    const std::string traces = dir.file("traces");
    const auto r = test::runCli("simulate --machine " + kMachine + " --plan " + kPlan + " --deviations " + kTruth + " --out " + traces);
    EXPECT_EQ(r.exitCode, 0) << r.out;
    return traces;
}

/// A cnccomp trace file split into its comment and header lines (kept as they are) and its data rows.
struct TraceText {
    std::string head;
    std::vector<std::string> rows;
};

TraceText readTraceText(const std::string& path) {
    std::ifstream in(path);
    TraceText t;
    std::string line;
    bool header = false;
    while (std::getline(in, line)) {
        if (line.empty() || line[0] == '#' || !header) {
            header = header || (!line.empty() && line[0] != '#');
            t.head += line + "\n";
        } else {
            t.rows.push_back(line);
        }
    }
    return t;
}

/// Rewrites the ΔL column (the last) of a cnccomp trace file, value ↦ value·factor.
void scaleTrace(const std::string& path, double factor) {
    const TraceText t = readTraceText(path);
    std::string out = t.head;
    for (const std::string& line : t.rows) {
        const size_t comma = line.rfind(',');
        out += line.substr(0, comma + 1) + fmt::format("{:.9g}", std::stod(line.substr(comma + 1)) * factor) + "\n";
    }
    test::writeText(path, out);
}

/// identify on these traces exits 2 naming mm and writes nothing.
void expectIdentifyRefusesMillimetres(const test::ScratchDir& dir, const std::string& traces) {
    const auto r = test::runCli("identify --machine " + kMachine + " --plan " + kPlan + " --traces " + traces + " --out " +
                                dir.file("d.csv"));
    EXPECT_EQ(r.exitCode, 2) << r.out;
    EXPECT_NE(r.out.find("likely in mm"), std::string::npos) << r.out;
    EXPECT_FALSE(fs::exists(dir.file("d.csv")));
}

template <typename F>
std::string inputErrorOf(F&& f) {
    try {
        f();
    } catch (const InputError& e) {
        return e.what();
    }
    return "(no InputError)";
}

// One mm export among µm files (identify gave EX0C1 5.34 µm for 12): refused, the file and "mm" named.
TEST(TraceUnits, OneFileInMillimetresAmongMicrometresIsRefused) {
    test::ScratchDir dir("io-traces-mm");
    const std::string traces = simulateInto(dir);
    const MeasurementPlan plan = readPlanXml(kPlan);
    ASSERT_NO_THROW(importRunTraces(traces, plan.runs));
    scaleTrace(traces + "/C-radial.csv", 1e-3);
    const std::string e = inputErrorOf([&] { importRunTraces(traces, plan.runs); });
    EXPECT_NE(e.find("C-radial.csv"), std::string::npos) << e;
    EXPECT_NE(e.find("likely in mm"), std::string::npos) << e;
    expectIdentifyRefusesMillimetres(dir, traces);
}

// The whole set exported in mm and read under the default µm (every result 1000× too small): no run spans
// what a ball bar resolves; refused naming mm. Oracle: the simulator's known truth (the same files in µm read).
TEST(TraceUnits, EveryFileInMillimetresIsRefused) {
    test::ScratchDir dir("io-traces-all-mm");
    const std::string traces = simulateInto(dir);
    const MeasurementPlan plan = readPlanXml(kPlan);
    for (const BallbarRun& r : plan.runs) scaleTrace(traces + "/" + r.name + ".csv", 1e-3);
    const std::string e = inputErrorOf([&] { importRunTraces(traces, plan.runs); });
    EXPECT_NE(e.find("likely in mm while the plan reads them in um"), std::string::npos) << e;
    EXPECT_NE(e.find("below the 0.1 um a ball bar resolves"), std::string::npos) << e;
    expectIdentifyRefusesMillimetres(dir, traces);
}

// µm data read under length-unit="mm": ΔL of millimetres, beyond any ball bar's travel; refused naming µm.
TEST(TraceUnits, MicrometreDataUnderMillimetreUnitIsRefused) {
    test::ScratchDir dir("io-traces-um");
    const std::string traces = simulateInto(dir);
    MeasurementPlan plan = readPlanXml(kPlan);
    for (BallbarRun& r : plan.runs) r.capture.lengthUnit = 1.0;
    const std::string e = inputErrorOf([&] { importRunTraces(traces, plan.runs); });
    EXPECT_NE(e.find("B-X.csv:"), std::string::npos) << e;
    EXPECT_NE(e.find("likely in um"), std::string::npos) << e;
    EXPECT_NE(e.find("±1 mm"), std::string::npos) << e;
}

/// Rewrites an angle-sampled cnccomp trace (one pass) with `per` samples a step, linearly interpolated between the
/// file's own samples.
void densify(const std::string& path, int per) {
    const TraceText t = readTraceText(path);
    std::string out = t.head;
    std::vector<std::pair<double, double>> rows;
    for (const std::string& line : t.rows) {
        const size_t comma = line.find(',');
        rows.emplace_back(std::stod(line.substr(0, comma)), std::stod(line.substr(comma + 1)));
    }
    for (size_t i = 0; i + 1 < rows.size(); ++i)
        for (int k = 0; k < per; ++k) {
            const double f = static_cast<double>(k) / per;
            out += fmt::format("{:.6f},{:.6f}\n", rows[i].first + f * (rows[i + 1].first - rows[i].first),
                               rows[i].second + f * (rows[i + 1].second - rows[i].second));
        }
    out += fmt::format("{:.6f},{:.6f}\n", rows.back().first, rows.back().second);
    test::writeText(path, out);
}

// A densely sampled file (a 38 MB trace took 81 s and 1.24 GB in identify) is averaged into bins of the
// plan's step: the same deviations as the file at the plan's step, the summary says so. Oracle: the plan-step files
// of the same simulation (the bins of a linear interpolant hold the plan's samples up to the curvature over a step).
// The speed is measured by BM_ImportDenseTrace (tests/bench), not here.
TEST(TraceUnits, DenseFileIsAveragedIntoThePlansStep) {
    test::ScratchDir dir("io-traces-dense");
    const std::string traces = simulateInto(dir);
    const auto plain = test::runCli("identify --machine " + kMachine + " --plan " + kPlan + " --traces " + traces +
                                    " --out " + dir.file("plain.csv"));
    ASSERT_EQ(plain.exitCode, 0) << plain.out;
    const MeasurementPlan plan = readPlanXml(kPlan);
    densify(traces + "/B-X.csv", 40);
    const MeasuredTrace t = importRunTrace(traces + "/B-X.csv", plan.runs.front());
    EXPECT_EQ(t.summary.binnedFrom, 359 * 40 + 1);  // a whole turn: -180..179°, 360 samples
    EXPECT_EQ(t.summary.binnedInto, 360);
    ASSERT_EQ(t.trace.angleDeg.size(), 360u);
    const auto dense = test::runCli("identify --machine " + kMachine + " --plan " + kPlan + " --traces " + traces +
                                    " --out " + dir.file("dense.csv"));
    ASSERT_EQ(dense.exitCode, 0) << dense.out;
    EXPECT_NE(dense.out.find("run B-X: 14361 samples averaged into 360 bins of the plan's 1° step"), std::string::npos)
        << dense.out;
    const MachineModel m = readMachineXml(kMachine);
    const DeviationSet a = readDeviationCsv(dir.file("plain.csv"), m), b = readDeviationCsv(dir.file("dense.csv"), m);
    for (size_t i = 0; i < m.deviations.size(); ++i)
        EXPECT_NEAR(a.isoValue(static_cast<int>(i)), b.isoValue(static_cast<int>(i)), 0.02 * kUm) << m.deviations[i].name;
}

// A folder standing where a trace belongs is named as a folder (it was called an "empty file").
TEST(TraceUnits, AFolderNamedLikeATraceIsNamed) {
    test::ScratchDir dir("io-traces-folder");
    const std::string traces = simulateInto(dir);
    fs::remove(traces + "/B-X.csv");
    fs::create_directories(traces + "/B-X.csv");
    const std::string e = inputErrorOf([&] { importRunTraces(traces, readPlanXml(kPlan).runs); });
    EXPECT_NE(e.find("B-X.csv: is a folder, not a file"), std::string::npos) << e;
}

}  // namespace
}  // namespace cnccomp
