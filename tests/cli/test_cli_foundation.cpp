// The main job end to end through the cnccomp executable: simulate → identify (closed form) → compare.
#include <gtest/gtest.h>

#include <filesystem>

#include "cnccomp/io/deviation_csv.hpp"
#include "test_support.hpp"

namespace cnccomp {
using namespace cnccomp::io;
namespace {

const std::string kMachine = test::sourcePath("samples/machines/multitasking.xml");
const std::string kPlan = test::sourcePath("samples/plans/multitasking-six-circles.xml");
const std::string kTruth = test::sourcePath("samples/deviations/multitasking-truth.csv");

TEST(CliFoundation, SimulateIdentifyCompareRecoversTheTruth) {
    test::ScratchDir dir("cli");
    const std::string traces = dir.file("traces");
    auto r = test::runCli("simulate --machine " + kMachine + " --plan " + kPlan + " --deviations " + kTruth + " --out " + traces);
    ASSERT_EQ(r.exitCode, 0) << r.out;
    for (const char* run : {"B-X", "B-Y", "C-axial", "C-radial", "C-radial-ZC2", "C-radial-RB2", "eccentricities"})
        EXPECT_TRUE(std::filesystem::exists(traces + "/" + run + ".csv")) << run;
    // From traces, and from the eccentricity table.
    for (const std::string& input : {"--traces " + traces + " --plan " + kPlan, "--eccentricities " + traces + "/eccentricities.csv"}) {
        const std::string out = dir.file("id.csv");
        r = test::runCli("identify --method closed-form --machine " + kMachine + " " + input + " --out " + out);
        ASSERT_EQ(r.exitCode, 0) << r.out;
        const MachineModel& m = test::multitasking();
        const DeviationSet id = readDeviationCsv(out, m), truth = readDeviationCsv(kTruth, m);
        for (size_t i = 0; i < m.deviations.size(); ++i) {
            if (!id.present[i]) continue;
            const auto& d = m.deviations[i];
            EXPECT_NEAR(id.values[d.offset], truth.values[d.offset], d.isAngle() ? 0.2 * kArcsec : 0.5 * kUm) << d.name;
        }
        r = test::runCli("compare --machine " + kMachine + " --truth " + kTruth + " --estimate " + out);
        ASSERT_EQ(r.exitCode, 0) << r.out;
        EXPECT_NE(r.out.find("largest difference"), std::string::npos);
    }
}

TEST(CliFoundation, NoiseIsSeededAndReproducible) {
    test::ScratchDir dir("cli-noise");
    for (const char* sub : {"a", "b"}) {
        auto r = test::runCli("simulate --machine " + kMachine + " --plan " + kPlan + " --deviations " + kTruth +
                              " --noise-um 0.5 --seed 42 --out " + dir.file(sub));
        ASSERT_EQ(r.exitCode, 0) << r.out;
    }
    EXPECT_EQ(test::readText(dir.file("a/B-X.csv")), test::readText(dir.file("b/B-X.csv")));
}

TEST(CliFoundation, ErrorsAreClearAndInputsAreNeverOverwritten) {
    test::ScratchDir dir("cli-err");
    const std::string before = test::readText(kTruth);
    auto r = test::runCli("identify --method closed-form --machine " + kMachine + " --eccentricities " + kTruth + " --out " + kTruth);
    EXPECT_EQ(r.exitCode, 2) << r.out;
    EXPECT_NE(r.out.find("refusing to overwrite"), std::string::npos) << r.out;
    EXPECT_EQ(test::readText(kTruth), before);

    test::writeText(dir.file("e.csv"), "test,LB_mm,RB_mm,RC_mm,ZC_mm,ex_um,ey_um,ez_um\nB-X,100,360,50,300,1,,2\n");
    r = test::runCli("identify --method closed-form --machine " + kMachine + " --eccentricities " + dir.file("e.csv") +
                     " --out " + dir.file("out.csv"));
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_NE(r.out.find("B-Y measurement is missing"), std::string::npos) << r.out;
    EXPECT_FALSE(std::filesystem::exists(dir.file("out.csv"))) << "no half file on failure";

    r = test::runCli("simulate --machine " + kMachine + " --plan " + kPlan + " --deviations " + dir.file("e.csv") + " --out " + dir.file("t"));
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_NE(r.out.find("e.csv"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace cnccomp
