// cnccomp identify (least squares, the default) and cnccomp plan end to end through the executable.
#include <gtest/gtest.h>

#include <filesystem>

#include "cnccomp/closed_form.hpp"
#include "cnccomp/eccentricity.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "cnccomp/io/report_json.hpp"
#include "cnccomp/io/trace_csv.hpp"
#include "test_support.hpp"

namespace cnccomp {
namespace {

const std::string kMachine = test::sourcePath("samples/machines/multitasking.xml");
const std::string kPlan = test::sourcePath("samples/plans/multitasking-six-circles.xml");
const std::string kTruth = test::sourcePath("samples/deviations/multitasking-truth.csv");

std::string simulateInto(const test::ScratchDir& dir, const std::string& plan, const std::string& extra = "") {
    const std::string traces = dir.file("traces");
    const auto r = test::runCli("simulate --machine " + kMachine + " --plan " + plan + " --deviations " + kTruth +
                                " --out " + traces + " " + extra);
    EXPECT_EQ(r.exitCode, 0) << r.out;
    return traces;
}

TEST(IdentifyCli, LeastSquaresIsTheDefaultAndRecoversAllThirteen) {
    test::ScratchDir dir("id-cli");
    const std::string traces = simulateInto(dir, kPlan);
    const auto r = test::runCli("identify --machine " + kMachine + " --plan " + kPlan + " --traces " + traces +
                                " --out " + dir.file("d.csv") + " --report " + dir.file("r.json"));
    ASSERT_EQ(r.exitCode, 0) << r.out;
    EXPECT_NE(r.out.find("levenberg-marquardt"), std::string::npos) << r.out;
    const MachineModel& m = test::multitasking();
    const DeviationSet id = readDeviationCsv(dir.file("d.csv"), m), truth = readDeviationCsv(kTruth, m);
    for (size_t i = 0; i < m.deviations.size(); ++i) {
        const DeviationDef& d = m.deviations[i];
        EXPECT_TRUE(id.present[i]) << d.name;  // γXY included: the raw traces see it
        // The CSV keeps 6 decimals of µm / arcsec.
        EXPECT_NEAR(id.values[d.offset], truth.values[d.offset], d.isAngle() ? 1e-3 * kArcsec : 1e-3 * kUm) << d.name;
    }
    const JsonValue j = readJsonFile(dir.file("r.json"));
    EXPECT_TRUE(j["converged"].boolean);
    EXPECT_EQ(j["rank"].num(), 13);
    EXPECT_EQ(j["observations"].num(), 6 * 360);
    EXPECT_EQ(j["runs"].array.size(), 6u);
    EXPECT_LT(j["runs"][0]["rms_after_um"].num(), 1e-6);
    EXPECT_EQ(j["unidentified"].array.size(), 0u);
    EXPECT_EQ(j["singular_values"].array.size(), 13u);
}

TEST(IdentifyCli, ClosedFormStillWorksExactly) {
    test::ScratchDir dir("id-cli-cf");
    const std::string traces = simulateInto(dir, kPlan);
    const auto r = test::runCli("identify --method closed-form --machine " + kMachine + " --plan " + kPlan +
                                " --traces " + traces + " --out " + dir.file("cf.csv"));
    ASSERT_EQ(r.exitCode, 0) << r.out;
    const MachineModel& m = test::multitasking();
    const MeasurementPlan plan = readPlanXml(kPlan);
    const DeviationSet lib = identifyClosedForm(m, eccentricitiesFromTraces(m, plan.runs, readRunTraces(traces, plan.runs)));
    EXPECT_EQ(test::readText(dir.file("cf.csv")), formatDeviationCsv(lib));
}

TEST(IdentifyCli, UnidentifiableRequestIsReportedByName) {
    test::ScratchDir dir("id-cli-unid");
    const std::string plan = test::sourcePath("samples/plans/lsq-multitasking-b-runs.xml");
    const std::string traces = simulateInto(dir, plan, "--noise-um 0.2 --seed 3");
    const auto r = test::runCli("identify --machine " + kMachine + " --plan " + plan + " --traces " + traces +
                                " --params dzBT,gXB,dxCZ,dyCZ,aCZ,bCZ --out " + dir.file("d.csv") + " --report " +
                                dir.file("r.json"));
    ASSERT_EQ(r.exitCode, 0) << r.out;
    EXPECT_NE(r.out.find("EX0C           dxCZ     unidentified"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("warning: 4 of 6 unknowns are not identifiable"), std::string::npos) << r.out;
    const JsonValue j = readJsonFile(dir.file("r.json"));
    ASSERT_EQ(j["unidentified"].array.size(), 4u);
    EXPECT_EQ(j["unidentified"][0].string, "EX0C");
    EXPECT_EQ(j["unidentified"][3].string, "EB0C");
    EXPECT_EQ(j["unobservable_directions"].array.size(), 4u);
    const DeviationSet id = readDeviationCsv(dir.file("d.csv"), test::multitasking());
    EXPECT_TRUE(id.present[test::multitasking().deviationIndex("gXB")]);
    EXPECT_FALSE(id.present[test::multitasking().deviationIndex("dxCZ")]);  // no meaningless value written
}

TEST(IdentifyCli, MonteCarloSolverAndStartOptions) {
    test::ScratchDir dir("id-cli-mc");
    const std::string traces = simulateInto(dir, kPlan, "--noise-um 0.5 --seed 9");
    auto r = test::runCli("identify --machine " + kMachine + " --plan " + kPlan + " --traces " + traces +
                          " --monte-carlo 20 --seed 4 --out " + dir.file("d.csv") + " --report " + dir.file("r.json"));
    ASSERT_EQ(r.exitCode, 0) << r.out;
    const JsonValue j = readJsonFile(dir.file("r.json"));
    EXPECT_EQ(j["monte_carlo_samples"].num(), 20);
    EXPECT_GT(j["parameters"][0]["mc_stddev"].num(), 0.0);
    EXPECT_NEAR(j["sigma_um"].num(), 0.5, 0.05);
    // NLopt with a bound; only a subset, the rest known from --start.
    r = test::runCli("identify --machine " + kMachine + " --plan " + kPlan + " --traces " + traces +
                     " --solver nlopt:LD_SLSQP --params dxCZ,dyCZ --bounds dxCZ=-10:10 --start " + kTruth + " --out " +
                     dir.file("n.csv"));
    ASSERT_EQ(r.exitCode, 0) << r.out;
    const DeviationSet n = readDeviationCsv(dir.file("n.csv"), test::multitasking());
    EXPECT_NEAR(n.get("dxCZ"), -10 * kUm, 1e-6 * kUm);  // truth −15 µm, held on the bound
    EXPECT_NEAR(n.get("dyCZ"), 10 * kUm, 1.0 * kUm);
}

TEST(IdentifyCli, BadInputFailsCleanlyWithoutOutputFiles) {
    test::ScratchDir dir("id-cli-bad");
    const std::string traces = simulateInto(dir, kPlan);
    const std::string base = "identify --machine " + kMachine + " --plan " + kPlan + " --traces " + traces;
    const std::string outs = " --out " + dir.file("d.csv") + " --report " + dir.file("r.json");
    auto r = test::runCli(base + " --params dxCZ,EQ7Q" + outs);
    EXPECT_NE(r.exitCode, 0);
    EXPECT_NE(r.out.find("unknown deviation 'EQ7Q'"), std::string::npos) << r.out;
    r = test::runCli(base + " --solver nlopt:NOT_AN_ALGORITHM" + outs);
    EXPECT_NE(r.exitCode, 0);
    EXPECT_NE(r.out.find("NOT_AN_ALGORITHM"), std::string::npos) << r.out;
    r = test::runCli(base + " --out " + kPlan);  // never overwrite an input
    EXPECT_NE(r.exitCode, 0);
    r = test::runCli(base + " --bounds dxCZ=5" + outs);
    EXPECT_NE(r.exitCode, 0);
    EXPECT_NE(r.out.find("NAME=LOWER:UPPER"), std::string::npos) << r.out;
    std::filesystem::remove(traces + "/C-axial.csv");
    r = test::runCli(base + outs);
    EXPECT_NE(r.exitCode, 0);
    EXPECT_NE(r.out.find("C-axial.csv"), std::string::npos) << r.out;
    test::writeText(traces + "/C-axial.csv", "angle_deg,dL_um\n0,0\n10,nan\n");
    r = test::runCli(base + outs);
    EXPECT_NE(r.exitCode, 0);
    EXPECT_NE(r.out.find("C-axial.csv:3"), std::string::npos) << r.out;
    EXPECT_FALSE(std::filesystem::exists(dir.file("d.csv")));
    EXPECT_FALSE(std::filesystem::exists(dir.file("r.json")));
}

TEST(IdentifyCli, PlanThenSimulateThenIdentify) {
    test::ScratchDir dir("plan-cli");
    auto r = test::runCli("plan --machine " + kMachine +
                          " --identify dxBT,dzBT,aBT,aXB,bXB,gXB,aYZ,bYZ,dxCZ,dyCZ,aCZ,bCZ --out " + dir.file("p.xml"));
    ASSERT_EQ(r.exitCode, 0) << r.out;
    EXPECT_NE(r.out.find("EC0Y (gXY)"), std::string::npos) << r.out;
    const MeasurementPlan p = readPlanXml(dir.file("p.xml"));
    EXPECT_LE(p.runs.size(), 6u);
    const std::string traces = simulateInto(dir, dir.file("p.xml"));
    r = test::runCli("identify --machine " + kMachine + " --plan " + dir.file("p.xml") + " --traces " + traces +
                     " --params dxBT,dzBT,aBT,aXB,bXB,gXB,aYZ,bYZ,dxCZ,dyCZ,aCZ,bCZ --start " + kTruth + " --out " +
                     dir.file("d.csv"));
    ASSERT_EQ(r.exitCode, 0) << r.out;
    r = test::runCli("compare --machine " + kMachine + " --truth " + kTruth + " --estimate " + dir.file("d.csv"));
    ASSERT_EQ(r.exitCode, 0) << r.out;
    EXPECT_NE(r.out.find("largest difference: 0.0000 um, 0.0000 arcsec"), std::string::npos) << r.out;
    // Eccentricity planning names the X-direction C run for γXY; bad requests fail with a message.
    r = test::runCli("plan --machine " + kMachine + " --observe eccentricity --identify dzBT,gXB,aYZ,bYZ,aCZ,bCZ --out " +
                     dir.file("e.xml"));
    ASSERT_EQ(r.exitCode, 0) << r.out;
    EXPECT_NE(r.out.find("EC0Y (gXY) [seen by C-X runs]"), std::string::npos) << r.out;
    r = test::runCli("plan --machine " + kMachine + " --identify gXB --candidates B-X,Q-Z --out " + dir.file("q.xml"));
    EXPECT_NE(r.exitCode, 0);
    EXPECT_NE(r.out.find("unknown run type 'Q-Z'"), std::string::npos) << r.out;
    r = test::runCli("plan --machine " + kMachine + " --identify gXB --out " + kMachine);
    EXPECT_NE(r.exitCode, 0);
    EXPECT_FALSE(std::filesystem::exists(dir.file("q.xml")));
}

}  // namespace
}  // namespace cnccomp
