// The main job (README command 1, tools/quickstart.sh) without its apt/build part, end to end in a scratch folder:
// every step's outputs are there, the identified set is the truth within the noise, the gated verifies pass, a
// compensation worse than none has its banner line in the summary and emit's warnings are printed, what emit
// predicts on the identified machine is what verify finds on the real (simulated) one, the ideal compensation and the
// corrected programs leave less than the noise, the reports load in headless Chromium. And the stand-in for the ball
// bar: `simulate --instrument` writes files in the instrument layout that identify imports like measured ones.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <sstream>

#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/json.hpp"
#include "cnccomp/io/report_json.hpp"
#include "test_browser.hpp"
#include "test_support.hpp"

namespace cnccomp {
using namespace cnccomp::io;
namespace {
namespace fs = std::filesystem;

const std::string kMachine = test::sourcePath("samples/machines/multitasking.xml");
const std::string kRecorded = test::sourcePath("samples/plans/multitasking-six-circles-recorded.xml");
const std::string kTruth = test::sourcePath("samples/deviations/multitasking-truth.csv");

/// One row of the summary table: "name  a -> b  c -> d  e -> f  left  report" ("-" where not known).
struct SummaryRow {
    double predictedBefore = NAN, predictedAfter = NAN, verifiedBefore = NAN, verifiedAfter = NAN, tipBefore = NAN, tipAfter = NAN;
    int left = -1;
    std::string report;
};

std::map<std::string, SummaryRow> readSummary(const std::string& text) {
    std::map<std::string, SummaryRow> rows;
    std::istringstream in(text);
    std::string line;
    std::getline(in, line);  // header
    while (std::getline(in, line) && !line.empty()) {
        std::istringstream w(line);
        std::string name;
        w >> name;
        SummaryRow r;
        const auto pair = [&](double& a, double& b) {
            std::string x, arrow, y;
            w >> x;
            if (x == "-") return;
            w >> arrow >> y;
            a = std::stod(x), b = std::stod(y);
        };
        pair(r.predictedBefore, r.predictedAfter);
        pair(r.verifiedBefore, r.verifiedAfter);
        pair(r.tipBefore, r.tipAfter);
        w >> r.left >> r.report;
        rows[name] = r;
    }
    return rows;
}

TEST(Quickstart, TheMainJobRunsTheWholeLoopAndKeepsEveryOutput) {
    test::ScratchDir dir("quickstart");
    const std::string out = dir.file("qs");
    const auto r = test::runCommand("bash " + test::sourcePath("tools/quickstart.sh") + " --no-build --cnccomp " + test::cliPath() +
                                    " --out " + out);
    ASSERT_EQ(r.exitCode, 0) << r.out;
    const auto file = [&](const std::string& rel) { return (fs::path(out) / rel).string(); };
    // 1 testprog, 2 the instrument files (time-sampled, CW then CCW), 3 identify with its report, 4 the map.
    EXPECT_TRUE(fs::exists(file("1-testprog/index.csv")));
    const std::vector<std::string> runs{"B-X", "B-Y", "C-axial", "C-radial", "C-radial-ZC2", "C-radial-RB2"};
    for (const std::string& run : runs) {
        const std::string t = test::readText(file("2-ballbar/" + run + ".csv"));
        EXPECT_NE(t.find("# run: " + run + "\n"), std::string::npos) << run;
        EXPECT_NE(t.find("\nt_s,dL_um,pass\n"), std::string::npos) << run;
        EXPECT_LT(t.find(",cw\n"), t.find(",ccw\n")) << run;
    }
    const MachineModel& m = test::multitasking();
    const DeviationSet id = readDeviationCsv(file("3-identify/deviations.csv"), m), truth = readDeviationCsv(kTruth, m);
    for (const DeviationDef& d : m.deviations)  // 0.2 µm noise on 4400 samples: within 0.5 µm / 0.5″
        EXPECT_NEAR(id.values[d.offset], truth.values[d.offset], d.isAngle() ? 0.5 * kArcsec : 0.5 * kUm) << d.name;
    const Json ir = readJsonFile(file("3-identify/report.summary.json"));
    EXPECT_EQ(ir["runs"].array.size(), 6u);
    EXPECT_EQ(ir["controllers"].array.size(), 6u);
    EXPECT_TRUE(fs::exists(file("4-map/map.svg")));
    // 5 emit for every controller, 6 the corrected part program and test programs.
    const std::vector<std::string> controllers{"fanuc-30i", "generic", "heidenhain-tnc", "isg", "linuxcnc", "siemens-840d"};
    for (const std::string& c : controllers) EXPECT_FALSE(fs::is_empty(file("5-emit/" + c))) << c;
    EXPECT_TRUE(fs::exists(file("6-correct/multitasking-5axis.ngc")));
    int corrected = 0;
    for (const auto& e : fs::directory_iterator(file("6-correct/testprog"))) corrected += e.path().extension() == ".ngc";
    EXPECT_EQ(corrected, 6);
    // 7 verify: a report and the JSON per compensation; the gated ones passed.
    std::vector<std::string> names{"ideal", "corrected-programs"};
    names.insert(names.end(), controllers.begin(), controllers.end());
    for (const std::string& n : names) {
        EXPECT_TRUE(fs::exists(file("7-verify/" + n + "/report.html"))) << n;
        EXPECT_EQ(readJsonFile(file("7-verify/" + n + "/report.summary.json"))["runs"].array.size(), 6u) << n;
        const Json v = readJsonFile(file("7-verify/" + n + "/verify.json"));
        if (n == "ideal" || n == "corrected-programs") {
            EXPECT_TRUE(v["passed"].boolean) << n;
        }
    }
    // The summary, printed and kept: every compensation, the same before on every row, the prediction holds.
    const std::string summary = test::readText(file("summary.txt"));
    EXPECT_NE(r.out.find(summary.substr(0, 200)), std::string::npos);
    const auto rows = readSummary(summary);
    ASSERT_EQ(rows.size(), names.size()) << summary;
    for (const std::string& n : names) {
        ASSERT_TRUE(rows.count(n)) << n << "\n" << summary;
        const SummaryRow& row = rows.at(n);
        EXPECT_NEAR(row.verifiedBefore, 70.25, 0.05) << n;  // the true machine's largest span, the same for every row
        EXPECT_EQ(row.report, file("7-verify/" + n + "/report.html"));
        if (n != "ideal" && n != "corrected-programs") {
            // What emit predicts on the identified machine is what verify finds on the real one, within the
            // identification's error (0.2 µm noise).
            EXPECT_NEAR(row.predictedAfter, row.verifiedAfter, 0.5) << n;
            EXPECT_TRUE(std::isfinite(row.tipAfter)) << n;
        }
    }
    EXPECT_LT(rows.at("ideal").verifiedAfter, 0.2);
    EXPECT_LT(rows.at("corrected-programs").verifiedAfter, 0.2);
    EXPECT_LT(rows.at("isg").verifiedAfter, 0.2);       // ISG's table holds every deviation of this machine
    // LinuxCNC's default route, the generated kinematics component, holds the whole model: nothing is left,
    // and the test programs give it their tool length (G43.1), so the span is that of a controller holding everything.
    EXPECT_EQ(rows.at("linuxcnc").left, 0);
    EXPECT_LT(rows.at("linuxcnc").verifiedAfter, 0.1);
    EXPECT_NE(r.out.find("every output: " + out + "/"), std::string::npos);
    // Every compensation that verify finds worse than none has its banner line in the summary, the others none; every
    // WARNING of emit is printed, not only kept in 5-emit/<c>.txt.
    for (const std::string& n : names) {
        const bool worse = readJsonFile(file("7-verify/" + n + "/verify.json"))["makes_machine_worse"].boolean;
        EXPECT_EQ(summary.find("!!! " + n + ": COMPENSATION MAKES THE MACHINE WORSE") != std::string::npos, worse) << n << "\n" << summary;
    }
    for (const std::string& c : controllers) {
        std::istringstream emitted(test::readText(file("5-emit/" + c + ".txt")));
        for (std::string line; std::getline(emitted, line);)
            if (line.find("WARNING") != std::string::npos) {
                EXPECT_NE(r.out.find(c + ": " + line), std::string::npos) << line;
            }
    }

    if (!test::chromium()) GTEST_SKIP() << "Chromium is not installed (Debian package chromium, tools/deps.sh): the browser check is skipped";
    for (const std::string page : {"3-identify/report.html", "7-verify/linuxcnc/report.html"}) {
        const std::string log = test::screenshot(file(page), dir.file("page.png"), 1400, 1600, dir);
        EXPECT_EQ(log.find("CONSOLE"), std::string::npos) << page << "\n" << log;
        std::string why;
        const auto pic = test::readPng(dir.file("page.png"), why);
        if (!pic) GTEST_SKIP() << "cannot read the screenshot: " << why;
        EXPECT_GT(test::countColour(*pic, "#1f4fd8"), 1000) << page;  // the polar plots' CCW trace is on the page
    }
}

TEST(Quickstart, AFolderItDidNotMakeIsNeverEmptied) {
    test::ScratchDir dir("quickstart-foreign");
    test::writeText(dir.file("mine.txt"), "keep me");
    const auto r = test::runCommand("bash " + test::sourcePath("tools/quickstart.sh") + " --no-build --cnccomp " + test::cliPath() +
                                    " --out " + dir.path.string());
    EXPECT_EQ(r.exitCode, 2) << r.out;
    EXPECT_NE(r.out.find("was not made by this script"), std::string::npos) << r.out;
    EXPECT_EQ(test::readText(dir.file("mine.txt")), "keep me");
}

TEST(Quickstart, SimulatedInstrumentFilesAreImportedLikeMeasuredOnes) {
    // Round trip: the truth comes back from files in the instrument's layouts (noise-free).
    test::ScratchDir dir("instrument");
    const MachineModel& m = test::multitasking();
    const DeviationSet truth = readDeviationCsv(kTruth, m);
    for (const std::string layout : {"time", "angle"}) {
        auto r = test::runCli("simulate --machine " + kMachine + " --plan " + kRecorded + " --deviations " + kTruth +
                              " --instrument " + layout + " --out " + dir.file(layout));
        ASSERT_EQ(r.exitCode, 0) << r.out;
        EXPECT_FALSE(fs::exists(dir.file(layout + "/eccentricities.csv")));
        const std::string t = test::readText(dir.file(layout + "/C-axial.csv"));
        EXPECT_NE(t.find(layout == "time" ? "\nt_s,dL_um,pass\n" : "\nangle_deg,dL_um,pass\n"), std::string::npos) << t.substr(0, 400);
        // CW from 364° down to −4°, then CCW back: 2 × 369 samples with the 4° overshoot at each end.
        EXPECT_NE(t.find(layout == "time" ? "\n0.0000000," : "\n364.0000000,"), std::string::npos);
        EXPECT_EQ(std::count(t.begin(), t.end(), '\n') - std::count(t.begin(), t.end(), '#'), 1 + 2 * 369);
        r = test::runCli("identify --machine " + kMachine + " --plan " + kRecorded + " --traces " + dir.file(layout) + " --out " +
                         dir.file(layout + ".csv"));
        ASSERT_EQ(r.exitCode, 0) << r.out;
        const DeviationSet id = readDeviationCsv(dir.file(layout + ".csv"), m);
        for (const DeviationDef& d : m.deviations)
            EXPECT_NEAR(id.values[d.offset], truth.values[d.offset], d.isAngle() ? 1e-3 * kArcsec : 1e-3 * kUm) << layout << " " << d.name;
    }
    // A time-sampled file needs the run's feed: the plain six-circle plan has none; nothing is written.
    auto r = test::runCli("simulate --machine " + kMachine + " --plan " + test::sourcePath("samples/plans/multitasking-six-circles.xml") +
                          " --deviations " + kTruth + " --instrument time --out " + dir.file("nofeed"));
    EXPECT_EQ(r.exitCode, 2) << r.out;
    EXPECT_NE(r.out.find("run 'B-X'"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("feed"), std::string::npos) << r.out;
    EXPECT_FALSE(fs::exists(dir.file("nofeed")));
    r = test::runCli("simulate --machine " + kMachine + " --plan " + kRecorded + " --instrument bar --out " + dir.file("bad"));
    EXPECT_EQ(r.exitCode, 2) << r.out;
    EXPECT_NE(r.out.find("'bar' is not time or angle"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace cnccomp
