// LinuxCNC pitch-error table from ISO 230-2 laser runs (controllers/linuxcnc/laser_comp.hpp) and `cnccomp laser`
// end to end. Oracles: a round trip through the table as LinuxCNC reads and applies it (parseCompTable, CompTable::trim
// as control.c compute_screw_comp), and hand cases for the sign (overshoot → negative trim; lost motion → positive
// BACKLASH, from LinuxCNC's ±BACKLASH/2 rule in control.c).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/laser_csv.hpp"
#include "cnccomp/laser_positioning.hpp"
#include "controllers/linuxcnc/comp_table.hpp"
#include "controllers/linuxcnc/laser_comp.hpp"
#include "test_support.hpp"

namespace cnccomp {
using namespace cnccomp::io;
namespace {

namespace lc = controllers::linuxcnc;
const std::string kSample = test::sourcePath("samples/laser/x-axis-iso230-2.csv");

/// Five runs, both directions, the same reading in every run: forward f(P), reverse r(P) (µm).
template <class F, class R>
LaserPositioningRuns constantRuns(const std::vector<double>& targets, F f, R r) {
    LaserPositioningRuns in;
    in.targets = targets;
    for (int j = 0; j < 5; ++j) {
        std::vector<double> fw, rv;
        for (double P : targets) {
            fw.push_back(f(P));
            rv.push_back(r(P));
        }
        in.forward.push_back(fw);
        in.reverse.push_back(rv);
    }
    return in;
}

// Round trip: the written table, read back as LinuxCNC reads it and applied as control.c applies it, cancels the
// measured mean deviations at the laser's own targets (to 1e-9 mm: the sample's readings have 0.01 um resolution, so
// the means are multiples of 2e-6 mm and the table's 7 decimals hold them exactly), and between the targets it is the
// negated piecewise-linear error x̄(P) of the evaluation.
TEST(LaserComp, TheWrittenTableCancelsTheMeasuredMeanDeviations) {
    const LaserPositioningResult r = evaluateLaserPositioning(readLaserCsv(kSample).runs);
    const lc::CompTable t = lc::parseCompTable(lc::formatCompTable(lc::compTableFromLaser(r), "X.comp"), "X.comp");
    ASSERT_EQ(t.nominal.size(), r.targets.size());
    for (const LaserTargetResult& p : r.targets) {
        EXPECT_NEAR(t.trim(p.target, +1) + p.meanForward / 1000, 0.0, 1e-9) << p.target;
        EXPECT_NEAR(t.trim(p.target, -1) + p.meanReverse / 1000, 0.0, 1e-9) << p.target;
    }
    for (double P = -10; P <= 510; P += 7.3) {
        EXPECT_NEAR(t.trim(P, +1) + r.errorAt(P, true) / 1000, 0.0, 1e-9) << P;
        EXPECT_NEAR(t.trim(P, -1) + r.errorAt(P, false) / 1000, 0.0, 1e-9) << P;
    }
}

// Sign by hand: the axis overshoots by +5 um at 100 mm (actual − target = +0.005 mm) in the forward direction, so the
// motor must be commanded 0.005 mm less there: trim −0.005 mm, the line "100.000000 -0.0050000 …".
TEST(LaserComp, AnOvershootGivesANegativeTrim) {
    const std::vector<double> targets = {0, 100, 200, 300, 400};
    const auto in = constantRuns(targets, [](double P) { return P == 100 ? 5.0 : 0.0; }, [](double) { return 0.0; });
    const std::string text = lc::formatCompTable(lc::compTableFromLaser(evaluateLaserPositioning(in)), "X.comp");
    EXPECT_NE(text.find("100.000000 -0.0050000 0.0000000\n"), std::string::npos) << text;
    EXPECT_NEAR(lc::parseCompTable(text, "X.comp").trim(100, +1), -0.005, 1e-12);
}

// BACKLASH alone: lost motion of 3 um (forward readings −1.5 um, reverse +1.5 um, B̄ = −3 um). LinuxCNC adds +BL/2
// moving up and −BL/2 moving down (control.c), so BL = +0.003 mm brings both to zero.
TEST(LaserComp, LostMotionGivesAPositiveBacklashAndTheIniLines) {
    const std::vector<double> targets = {0, 100, 200, 300, 400};
    const auto r = evaluateLaserPositioning(constantRuns(targets, [](double) { return -1.5; }, [](double) { return 1.5; }));
    const double bl = lc::backlashFromLaser(r);
    EXPECT_NEAR(bl, 0.003, 1e-12);
    EXPECT_NEAR(-1.5 / 1000 + bl / 2, 0.0, 1e-12);
    EXPECT_NEAR(1.5 / 1000 - bl / 2, 0.0, 1e-12);
    const std::string ini = lc::laserCompIniLines(r, 2, "X.comp");
    EXPECT_EQ(ini.rfind("[JOINT_2]\nCOMP_FILE = X.comp\nCOMP_FILE_TYPE = 1\n", 0), 0u) << ini;
    EXPECT_NE(ini.find("BACKLASH = 0.003000"), std::string::npos) << ini;
    // The table alone does what BACKLASH would: forward trim +0.0015, reverse −0.0015 (LinuxCNC's ±BL/2).
    const lc::CompTable t = lc::compTableFromLaser(r);
    EXPECT_NEAR(t.trim(200, +1), bl / 2, 1e-12);
    EXPECT_NEAR(t.trim(200, -1), -bl / 2, 1e-12);
}

TEST(LaserComp, MoreTargetsThanLinuxCncHoldsIsAModelError) {
    std::vector<double> targets;
    for (int i = 0; i <= lc::kMaxCompLines; ++i) targets.push_back(i);
    const auto r = evaluateLaserPositioning(constantRuns(targets, [](double) { return 0.0; }, [](double) { return 1.0; }));
    EXPECT_THROW(lc::compTableFromLaser(r), ModelError);
}

TEST(LaserCli, PrintsTheTableWritesJsonAndTheCompFileTogether) {
    test::ScratchDir dir("laser-cli");
    const auto r = test::runCli("laser --file " + kSample + " --json " + dir.file("r.json") + " --comp-out " +
                                dir.file("comp") + " --joint 0");
    ASSERT_EQ(r.exitCode, 0) << r.out;
    for (const char* part : {"ISO 230-2 positioning of axis X: 11 targets, 5 runs", "environment compensation: done",
                             "E  =", "A  =", "B  =", "B-bar =", "R  =", "M  =", "[JOINT_0]", "COMP_FILE = X.comp",
                             "COMP_FILE_TYPE = 1"})
        EXPECT_NE(r.out.find(part), std::string::npos) << part << "\n" << r.out;
    EXPECT_NE(r.out.find("wrote " + dir.file("comp/X.comp")), std::string::npos) << r.out;
    const lc::CompTable t = lc::parseCompTable(test::readText(dir.file("comp/X.comp")), "X.comp");
    EXPECT_EQ(t.nominal.size(), 11u);
    EXPECT_NE(test::readText(dir.file("r.json")).find("\"schema\": \"cnccomp-laser-positioning/1\""), std::string::npos);
}

TEST(LaserCli, BadInputExitsTwoAndWritesNothing) {
    test::ScratchDir dir("laser-cli-bad");
    std::string one = "# axis: X\ntarget_mm,run,direction,deviation_um\n";
    for (int j = 1; j <= 5; ++j)
        for (int i = 0; i < 5; ++i) one += fmt::format("{},{},+,0.5\n", 100 * i, j);
    test::writeText(dir.file("one.csv"), one);
    auto r = test::runCli("laser --file " + dir.file("one.csv") + " --json " + dir.file("r.json") + " --comp-out " +
                          dir.file("comp") + " --joint 0");
    EXPECT_EQ(r.exitCode, 2) << r.out;
    EXPECT_NE(r.out.find(dir.file("one.csv") + ": laser positioning of axis X: runs in one direction only"),
              std::string::npos) << r.out;
    r = test::runCli("laser --file " + kSample + " --json " + dir.file("r.json") + " --comp-out " + dir.file("comp"));
    EXPECT_EQ(r.exitCode, 2) << r.out;
    EXPECT_NE(r.out.find("--comp-out needs --joint N"), std::string::npos) << r.out;
    r = test::runCli("laser --file " + kSample + " --json " + kSample);
    EXPECT_EQ(r.exitCode, 2) << r.out;
    EXPECT_FALSE(std::filesystem::exists(dir.file("r.json")));
    EXPECT_FALSE(std::filesystem::exists(dir.file("comp")));
}

}  // namespace
}  // namespace cnccomp
