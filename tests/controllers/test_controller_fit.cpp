// The values a controller's files carry, fitted to what that controller holds (controllers/common/fit.hpp):
// never more tool-tip error than no compensation, the identified values where the controller holds them all,
// the quickstart machine's Fanuc files better than none, --copy-identified unchanged, the warning's tolerance.
// Oracles: the evaluation harness (exact kinematics of the identified machine with the files read back by each
// backend's own apply model), round trips (files byte for byte), and the issue's own figures for the Fanuc case.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "app/verify.hpp"
#include "controllers/common/evaluate.hpp"
#include "controllers/common/fit.hpp"
#include "controller_test_util.hpp"
#include "test_support.hpp"

namespace cnccomp {
using namespace cnccomp::io;
using namespace cnccomp::measurement;
namespace {

std::string src(const std::string& rel) { return test::sourcePath(rel); }

/// Every sample machine with a deviation set of its own (the samples' truth or controller sets).
const std::map<std::string, std::string> kSampleSets = {
    {"controllers-fanuc-pitch", "controllers-fanuc-pitch.csv"},
    {"controllers-heidenhain-components", "controllers-heidenhain-components.csv"},
    {"controllers-siemens-components", "controllers-siemens-components.csv"},
    {"controllers-table-table-ac", "controllers-table-table-ac.csv"},
    {"controllers-tilting-head-b", "controllers-tilting-head-b.csv"},
    {"multitasking", "multitasking-truth.csv"},
    {"table-table-ac", "table-table-ac-truth.csv"},
    {"table-table-bc-offsets", "table-table-bc-offsets-truth.csv"},
    {"table-table-bc", "dbb5-table-table-bc-truth.csv"},
    {"tilting-head-b", "tilting-head-b-truth.csv"},
};

controllers::common::FitWorkspace smallWorkspace(const MachineModel& m, int perAxis = 3) {
    controllers::common::FitWorkspace w;
    w.poses = controllers::common::workspaceSamples(m, perAxis);
    w.toolLengths = {0.0, 100.0};
    w.description = fmt::format("{} per axis over the travel, tools 0 100 mm", perAxis);
    return w;
}

/// No compensation (drives get the commands) over the workspace: the reference every chosen file set must not exceed.
controllers::common::FitFigures noCompensation(const MachineModel& m, const DeviationSet& d, const controllers::common::FitWorkspace& w) {
    controllers::common::FitFigures f;
    double sum = 0;
    long n = 0;
    for (double L : w.toolLengths) {
        const auto c = controllers::common::evaluateCompensation(m, d, controllers::common::NoCompensation{}, w.poses, L);
        f.maxTip = std::max(f.maxTip, c.maxBefore);
        sum += c.rmsBefore * c.rmsBefore * c.points;
        n += c.points;
    }
    f.rmsTip = std::sqrt(sum / static_cast<double>(n));
    return f;
}

/// One sample machine per test (a ctest entry each: the suite's two jobs share them out).
class ChosenFiles : public ::testing::TestWithParam<std::string> {};

TEST_P(ChosenFiles, NeverLeaveMoreThanNoneWithAnyBackend) {
    // The choice is made on the workspace itself, zero compensation among the candidates; checked here independently:
    // the written values emitted and read back by the backend, against the machine with no compensation at all.
    int pairs = 0;
    {
        const std::string stem = GetParam();
        const std::string set = kSampleSets.at(stem);
        const MachineModel& m = test::sampleMachine(stem);
        const DeviationSet d = readDeviationCsv(src("samples/deviations/" + set), m);
        // The travel's ends (2 per axis): the emits of the fit's Jacobian cost more than the poses.
        const controllers::common::FitWorkspace w = smallWorkspace(m, 2);
        // No compensation over the poses the candidates are judged on (the grid and each axis' sweep, fit.hpp).
        const controllers::common::FitFigures none = noCompensation(m, d, controllers::common::judgedWorkspace(m, w));
        for (const controllers::Backend* b : controllers::backends()) {
            try {
                (void)b->emit(controllers::EmitRequest{m, d, "x", "2000-01-01"});
            } catch (const ModelError& e) {
                std::printf("  %-34s %-16s not emitted: %s\n", stem.c_str(), std::string(b->name()).c_str(), e.what());
                continue;
            }
            SCOPED_TRACE(fmt::format("{} / {}", stem, b->name()));
            const auto t0 = std::chrono::steady_clock::now();
            const controllers::common::FitOutcome o = controllers::common::fitControllerValues(*b, m, d, w);
            const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
            const controllers::common::FitFigures chosen = controllers::common::fitFigures(*b, m, d, o.written, w);
            EXPECT_FALSE(controllers::common::leavesMore(chosen, none))
                << fmt::format("chosen '{}' leaves max {:.4f} RMS {:.4f} um; none {:.4f} / {:.4f}", o.chosen, chosen.maxTip / kUm,
                               chosen.rmsTip / kUm, none.maxTip / kUm, none.rmsTip / kUm);
            // The figures the fit reports for its choice are those of the files it writes.
            const controllers::common::FitFigures& reported = o.chosen == "none" ? o.none : o.chosen == "identified" ? o.copied : o.fitted;
            EXPECT_NEAR(reported.maxTip, chosen.maxTip, 1e-9);
            EXPECT_NEAR(reported.rmsTip, chosen.rmsTip, 1e-9);
            // The fit never does worse (RMS) than the copy or none where it is chosen.
            EXPECT_LE(chosen.rmsTip, std::min(o.copied.rmsTip, o.none.rmsTip) + 1e-12);
            std::printf("  %-34s %-16s none %7.3f/%7.3f  copied %7.3f/%7.3f  fitted %7.3f/%7.3f  -> %s (%d values, %.2f s)\n",
                        stem.c_str(), std::string(b->name()).c_str(), o.none.maxTip / kUm, o.none.rmsTip / kUm, o.copied.maxTip / kUm,
                        o.copied.rmsTip / kUm, o.fitted.maxTip / kUm, o.fitted.rmsTip / kUm, o.chosen.c_str(), o.heldValues, seconds);
            ++pairs;
        }
    }
    EXPECT_EQ(pairs, static_cast<int>(controllers::backends().size()));  // every backend emits on every sample machine
}

INSTANTIATE_TEST_SUITE_P(ControllerFit, ChosenFiles, ::testing::ValuesIn([] {
                             std::vector<std::string> stems;
                             for (const auto& [stem, set] : kSampleSets) stems.push_back(stem);
                             return stems;
                         }()),
                         [](const ::testing::TestParamInfo<std::string>& i) {
                             std::string n = i.param;
                             for (char& c : n) c = c == '-' ? '_' : c;
                             return n;
                         });

TEST(ControllerFit, TheGenericMapIsNotFittedItsCopyIsJudged) {
    // The generic files hold the tip error itself, sampled (controllers/generic/grid_map.hpp): fitting deviation values
    // to them only bends the sampled error (measured before this rule on this machine: 99 s of fitting for a fit that
    // left RMS 2.269 against the copy's 1.997 um, not written). The candidates are none and the copy.
    const MachineModel& m = test::sampleMachine("controllers-heidenhain-components");
    const DeviationSet d = readDeviationCsv(src("samples/deviations/controllers-heidenhain-components.csv"), m);
    const controllers::Backend& b = controllers::backend("generic");
    EXPECT_FALSE(b.fitsDeviationValues());
    EXPECT_TRUE(controllers::backend("fanuc-30i").fitsDeviationValues());
    const controllers::common::FitOutcome o = controllers::common::fitControllerValues(b, m, d, smallWorkspace(m, 2));
    EXPECT_EQ(o.heldValues, -1);
    EXPECT_EQ(o.chosen, "identified");
    EXPECT_TRUE(o.written.values == d.values);
    EXPECT_LT(o.copied.maxTip, 0.2 * o.none.maxTip);
    ASSERT_FALSE(o.notes.empty());
    EXPECT_NE(o.notes.front().find("not fitted"), std::string::npos) << o.notes.front();
}

TEST(ControllerFit, BackendsHoldingEveryDeviationWriteTheIdentifiedValues) {
    // Where Siemens (CEC/EEC + kinematic chain), Heidenhain (kinematics + KinematicsComp), ISG and the generic map hold
    // every deviation of the set (their NOT-compensated list is empty): the fit is the identified values, exactly, and the
    // files are those of the copy.
    for (const std::string stem : {"multitasking", "table-table-ac", "tilting-head-b"}) {
        const MachineModel& m = test::sampleMachine(stem);
        const DeviationSet d = readDeviationCsv(src("samples/deviations/" + kSampleSets.at(stem)), m);
        const controllers::common::FitWorkspace w = smallWorkspace(m);
        for (const char* name : {"siemens-840d", "heidenhain-tnc", "isg", "generic"}) {
            SCOPED_TRACE(fmt::format("{} / {}", stem, name));
            const controllers::Backend& b = controllers::backend(name);
            if (!b.emit(controllers::EmitRequest{m, d, "x", "2000-01-01"}).notCompensated.empty()) continue;  // e.g. Siemens: EAB
            const controllers::common::FitOutcome o = controllers::common::fitControllerValues(b, m, d, w);
            EXPECT_EQ(o.chosen, "fitted");
            ASSERT_EQ(o.written.values.size(), d.values.size());
            EXPECT_TRUE(o.written.values == d.values);
            EXPECT_TRUE(o.written.present == d.present);
            const auto copy = b.emit(controllers::EmitRequest{m, d, "x", "2000-01-01"});
            const auto fitted = b.emit(controllers::EmitRequest{m, o.written, "x", "2000-01-01"});
            ASSERT_EQ(copy.files.size(), fitted.files.size());
            for (size_t i = 0; i < copy.files.size(); ++i) EXPECT_EQ(copy.files[i].content, fitted.files[i].content);
            EXPECT_LT(o.fitted.maxTip, 0.05 * o.none.maxTip);
        }
    }
}

TEST(ControllerFit, FanucOnTheQuickstartMachineLeavesClearlyLessThanNone) {
    // The case: the 30i holds the spindle offset and the C position (19700-19711) but not the B zero, tilts and
    // squareness, which partly cancelled them. Copied, the files leave MORE than none (73.3 against 67.3 um); fitted over
    // the plan's workspace and the travel, clearly less. Measured (figures over the workspace and each axis' sweep,
    // fit.hpp judgedWorkspace): none 67.3 / 28.3, copied 73.3 / 25.9, fitted 56.2 / 18.9 um (max / RMS) with the 4 deviations of this machine the files respond to (EX0C1 EZ0C1 EX0C EY0C). The
    // issue's independent fit (39.7 / 18.2 um) also moved parameters no deviation of this machine reaches (the spindle's Y
    // offset 19710, a constant shift of the tip).
    const MachineModel& m = test::multitasking();
    const DeviationSet d = readDeviationCsv(src("samples/deviations/multitasking-truth.csv"), m);
    const MeasurementPlan plan = readPlanXml(src("samples/plans/multitasking-six-circles-recorded.xml"));
    const app::PlanWorkspace p = app::planWorkspace(m, plan);
    controllers::common::FitWorkspace w;
    w.poses = p.poses;
    const auto travel = controllers::common::workspaceSamples(m, 5);
    w.poses.insert(w.poses.end(), travel.begin(), travel.end());
    w.toolLengths = {0.0, 100.0};
    for (double L : p.toolLengths)
        if (std::find(w.toolLengths.begin(), w.toolLengths.end(), L) == w.toolLengths.end()) w.toolLengths.push_back(L);
    const controllers::common::FitOutcome o = controllers::common::fitControllerValues(controllers::backend("fanuc-30i"), m, d, w);
    std::printf("fanuc-30i on multitasking: none %.3f/%.3f  copied %.3f/%.3f  fitted %.3f/%.3f um (%d values)\n", o.none.maxTip / kUm,
                o.none.rmsTip / kUm, o.copied.maxTip / kUm, o.copied.rmsTip / kUm, o.fitted.maxTip / kUm, o.fitted.rmsTip / kUm,
                o.heldValues);
    EXPECT_EQ(o.chosen, "fitted");
    EXPECT_TRUE(controllers::common::leavesMore(o.copied, o.none));  // the problem the issue reports
    EXPECT_LT(o.fitted.maxTip, 0.85 * o.none.maxTip);
    EXPECT_LT(o.fitted.rmsTip, 0.75 * o.none.rmsTip);
    EXPECT_GT(o.heldValues, 0);
}

TEST(ControllerFit, CopyIdentifiedWritesTodaysFilesByteForByte) {
    // Round trip: `emit --copy-identified` against the backend's emit of the identified set as it is.
    test::ScratchDir dir("fit-copy");
    const std::string mPath = src("samples/machines/multitasking.xml"), dPath = src("samples/deviations/multitasking-truth.csv");
    const MachineModel m = readMachineXml(mPath);
    const DeviationSet d = readDeviationCsv(dPath, m);
    for (const controllers::Backend* b : controllers::backends()) {
        SCOPED_TRACE(std::string(b->name()));
        const std::string out = dir.file(std::string(b->name()));
        const auto r = test::runCli(fmt::format("emit --controller {} --machine {} --deviations {} --out {} --date 2001-02-03 "
                                                "--copy-identified --fit-grid 3",
                                                b->name(), mPath, dPath, out));
        ASSERT_EQ(r.exitCode, 0) << r.out;
        EXPECT_NE(r.out.find("not computed (--copy-identified)"), std::string::npos) << r.out;
        const auto today = b->emit(controllers::EmitRequest{m, d, "multitasking-truth.csv", "2001-02-03"});
        for (const auto& f : today.files) EXPECT_EQ(test::readText((std::filesystem::path(out) / f.name).string()), f.content) << f.name;
    }
}

TEST(ControllerFit, EmitPrintsTheThreeCandidatesAndTheFitInEveryFileHeader) {
    test::ScratchDir dir("fit-emit");
    const std::string m = src("samples/machines/multitasking.xml"), p = src("samples/plans/multitasking-six-circles-recorded.xml"),
                      t = src("samples/deviations/multitasking-truth.csv");
    const auto r = test::runCli("emit --controller fanuc-30i --machine " + m + " --deviations " + t + " --plan " + p +
                                " --fit-tool-lengths 0,100,360 --out " + dir.file("f"));
    ASSERT_EQ(r.exitCode, 0) << r.out;
    for (const char* key : {"none", "identified values copied", "fitted", "tool tip max / RMS (um)", "largest span (um)",
                            "tool lengths 0 100 360 mm", "written: the fitted values", "predicted residual on the identified machine"})
        EXPECT_NE(r.out.find(key), std::string::npos) << key << "\n" << r.out;
    EXPECT_EQ(r.out.find("WARNING"), std::string::npos) << r.out;
    for (const auto& e : std::filesystem::directory_iterator(dir.file("f"))) {
        const std::string text = test::readText(e.path().string());
        EXPECT_NE(text.find("values fitted to this controller"), std::string::npos) << e.path();
        EXPECT_NE(text.find("tool lengths 0 100 360 mm"), std::string::npos) << e.path();
    }
    // Bad options: a clear error, exit 2, nothing written.
    auto bad = test::runCli("emit --controller fanuc-30i --machine " + m + " --deviations " + t + " --fit-grid 0 --out " + dir.file("g"));
    EXPECT_EQ(bad.exitCode, 2) << bad.out;
    EXPECT_NE(bad.out.find("--fit-grid"), std::string::npos) << bad.out;
    bad = test::runCli("emit --controller fanuc-30i --machine " + m + " --deviations " + t + " --fit-tool-lengths 0,-5 --out " +
                       dir.file("g"));
    EXPECT_EQ(bad.exitCode, 2) << bad.out;
    EXPECT_NE(bad.out.find("--fit-tool-lengths"), std::string::npos) << bad.out;
    EXPECT_FALSE(std::filesystem::exists(dir.file("g")));
}

TEST(ControllerFit, TheWarningHasATolerance) {
    // 1 % or 0.01 um, whichever is larger: equal figures (0.001 vs 0.001 um, 76.574 vs 76.574 um) and rounding never warn.
    const auto fig = [](double maxUm, double rmsUm) { return controllers::common::FitFigures{maxUm * kUm, rmsUm * kUm, 0}; };
    EXPECT_FALSE(controllers::common::leavesMore(fig(0.001, 0.001), fig(0.001, 0.001)));
    EXPECT_FALSE(controllers::common::leavesMore(fig(76.574, 30), fig(76.574, 30)));
    EXPECT_FALSE(controllers::common::leavesMore(fig(0.009, 0.009), fig(0.0, 0.0)));
    EXPECT_TRUE(controllers::common::leavesMore(fig(0.011, 0.0), fig(0.0, 0.0)));
    EXPECT_FALSE(controllers::common::leavesMore(fig(76.574 * 1.009, 30), fig(76.574, 30)));
    EXPECT_TRUE(controllers::common::leavesMore(fig(76.574 * 1.011, 30), fig(76.574, 30)));
    EXPECT_TRUE(controllers::common::leavesMore(fig(50, 30.4), fig(76.574, 30)));
    // Through the CLI (the warning printed by emit, and none where the files hold everything):
    // Verify.EmitWarnsWhenItsFilesLeaveMoreThanNoCompensation.
}

TEST(ControllerFit, FanucOnTheTableTableAcMachineNeverMakesTheRtestWorse) {
    // Found today: emit fanuc-30i on table-table-ac with the truth set (default 5-per-axis grid) said fitted 129.5 / 53.4
    // um against none 164.5 / 86.7 and wrote pitch tables of A and C whose nodes moved together by 9 deg (a constant part
    // a pitch table cannot hold) and stayed zero between the grid's samples; `cnccomp verify` with the R-test plan then
    // measured the span 76.574 -> 63833.996 um (exit 1). Oracle: verify runs the plan's test programs through exactly the
    // files written (a different path from the fit's own figures). Measured after the fix: span 76.574 -> 76.574 um,
    // volumetric max 136.898 -> 107.480 um, constant parts 34 / -4 arcsec.
    test::ScratchDir dir("fit-fanuc-ac");
    const std::string mPath = src("samples/machines/table-table-ac.xml"), dPath = src("samples/deviations/table-table-ac-truth.csv"),
                      pPath = src("samples/plans/table-table-ac-rtest.xml");
    const auto e = test::runCli("emit --controller fanuc-30i --machine " + mPath + " --deviations " + dPath + " --date 2001-02-03 --out " +
                                dir.file("f"));
    ASSERT_EQ(e.exitCode, 0) << e.out;
    // No degrees of constant pitch offset in the file: every "(constant part) N arcsec" well under a degree.
    for (size_t at = e.out.find("(constant part)"); at != std::string::npos; at = e.out.find("(constant part)", at + 1)) {
        const double arcsec = std::stod(e.out.substr(at + 15));
        EXPECT_LT(std::abs(arcsec), 360.0) << e.out;
    }
    const auto v = test::runCli("verify --machine " + mPath + " --plan " + pPath + " --compensation " + dir.file("f") + " --truth " + dPath);
    EXPECT_EQ(v.exitCode, 0) << v.out;  // exit 1: "COMPENSATION MAKES THE MACHINE WORSE"
    const std::string key = "residual (largest span after compensation): ";
    const size_t at = v.out.find(key);
    ASSERT_NE(at, std::string::npos) << v.out;
    const double after = std::stod(v.out.substr(at + key.size()));
    const size_t b = v.out.find("(before: ", at);
    ASSERT_NE(b, std::string::npos) << v.out;
    const double before = std::stod(v.out.substr(b + 9));
    std::printf("fanuc-30i on table-table-ac, R-test span %.3f -> %.3f um\n", before, after);
    EXPECT_LE(after, before + std::max(0.01, 0.01 * before)) << v.out;
    const size_t vol = v.out.find("  max ", v.out.find("volumetric tool-tip error"));
    ASSERT_NE(vol, std::string::npos) << v.out;
    const double volBefore = std::stod(v.out.substr(vol + 6));
    const double volAfter = std::stod(v.out.substr(v.out.find("-> ", vol) + 3));
    EXPECT_LT(volAfter, volBefore) << v.out;
}

TEST(ControllerFit, RtestPlansSayDisplacementNotSpan) {
    test::ScratchDir dir("fit-rtest");
    const auto r = test::runCli("emit --controller fanuc-30i --machine " + src("samples/machines/table-table-ac.xml") + " --deviations " +
                                src("samples/deviations/table-table-ac-truth.csv") + " --plan " +
                                src("samples/plans/table-table-ac-rtest.xml") + " --fit-grid 3 --out " + dir.file("f"));
    ASSERT_EQ(r.exitCode, 0) << r.out;
    EXPECT_NE(r.out.find("largest R-test displacement (um)"), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find("ball-bar span"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace cnccomp
