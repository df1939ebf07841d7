// cnccomp simulate, cnccomp identify (every kind of plan, least squares by default) and cnccomp plan end to end through
// the executable.
#include <gtest/gtest.h>

#include <filesystem>

#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "cnccomp/io/json.hpp"
#include "cnccomp/io/report_json.hpp"
#include "cnccomp/io/trace_csv.hpp"
#include "test_support.hpp"

namespace cnccomp {
using namespace cnccomp::io;
using namespace cnccomp::measurement;
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
    const Json j = readJsonFile(dir.file("r.json"));
    EXPECT_TRUE(j["converged"].boolean);
    EXPECT_EQ(j["rank"].num(), 13);
    EXPECT_EQ(j["observations"].num(), 6 * 360);
    EXPECT_EQ(j["runs"].array.size(), 6u);
    EXPECT_LT(j["runs"][0]["rms_after_um"].num(), 1e-6);
    EXPECT_EQ(j["unidentified"].array.size(), 0u);
    EXPECT_EQ(j["singular_values"].array.size(), 13u);
}

// ClosedFormStillWorksExactly and UnidentifiableRequestIsReportedByName call the façade now
// (tests/app/test_identify_facade.cpp).

TEST(IdentifyCli, MonteCarloSolverAndStartOptions) {
    test::ScratchDir dir("id-cli-mc");
    const std::string traces = simulateInto(dir, kPlan, "--noise-um 0.5 --seed 9");
    auto r = test::runCli("identify --machine " + kMachine + " --plan " + kPlan + " --traces " + traces +
                          " --monte-carlo 20 --seed 4 --out " + dir.file("d.csv") + " --report " + dir.file("r.json"));
    ASSERT_EQ(r.exitCode, 0) << r.out;
    const Json j = readJsonFile(dir.file("r.json"));
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
    // The unknowns are ISO values: a bound under an alias of another sign (gXY = −EC0Y) is refused, not flipped.
    r = test::runCli(base + " --solver nlopt:LD_SLSQP --params gXY,dxCZ --bounds gXY=-5:5" + outs);
    EXPECT_EQ(r.exitCode, 2) << r.out;
    EXPECT_NE(r.out.find("under the ISO name 'EC0Y'"), std::string::npos) << r.out;
    std::filesystem::remove(traces + "/C-axial.csv");
    // The options are checked before any trace is read: the misspelt solver is named, not the missing file.
    r = test::runCli(base + " --solver nlopt:NOT_AN_ALGORITHM" + outs);
    EXPECT_EQ(r.exitCode, 2) << r.out;
    EXPECT_NE(r.out.find("unknown NLopt algorithm 'NOT_AN_ALGORITHM'"), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find("C-axial.csv"), std::string::npos) << r.out;
    r = test::runCli(base + " --solver gauss" + outs);  // an unknown solver: named with what --solver accepts
    EXPECT_EQ(r.exitCode, 2) << r.out;
    EXPECT_NE(r.out.find("unknown --solver 'gauss' (lm, or nlopt:<ALGORITHM>"), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find("C-axial.csv"), std::string::npos) << r.out;
    r = test::runCli(base + " --rank-tolerance 2" + outs);
    EXPECT_EQ(r.exitCode, 2) << r.out;
    EXPECT_NE(r.out.find("rank tolerance must be in (0, 1)"), std::string::npos) << r.out;
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

TEST(IdentifyCli, SimulateWritesNothingWhenALaterRunFails) {
    // A half-written output once stayed behind: the first run is fine, the second leaves the X travel (RC = 5 m); no trace of the first may remain.
    test::ScratchDir dir("sim-fail");
    test::writeText(dir.file("p.xml"), R"(<plan machine="multitasking">
  <run name="ok" test="B-X" LB="100" RB="200" RC="50" ZC="100" start="-180" end="180" step="10"/>
  <run name="far" test="C-radial" LB="100" RB="200" RC="5000" ZC="100" start="0" end="360" step="10"/>
</plan>
)");
    const auto r = test::runCli("simulate --machine " + kMachine + " --plan " + dir.file("p.xml") + " --deviations " + kTruth +
                                " --out " + dir.file("out"));
    EXPECT_EQ(r.exitCode, 2) << r.out;
    EXPECT_NE(r.out.find("travel"), std::string::npos) << r.out;
    EXPECT_FALSE(std::filesystem::exists(dir.file("out/ok.csv")));
    EXPECT_FALSE(std::filesystem::exists(dir.file("out")));
}

TEST(IdentifyCli, EveryKindOfPlanGoesThroughTheSameTwoCommands) {
    // Noise-free round trips through simulate and identify for the plans that are not ball-bar circles, both methods;
    // the printed truth difference is the check (the library tests check each method's accuracy in detail).
    struct Case {
        const char* machine;
        const char* plan;
        const char* truth;
        const char* kind;
        double tolUm, tolArcsec;  // formulas: the printed or refined formulas' accuracy on these samples
    };
    const Case cases[] = {
        {"tilting-head-b", "tilting-head-b-patterns", "tilting-head-b-truth", "head patterns", 0.01, 0.01},
        {"table-table-ac", "dbb5-table-table-ac", "dbb5-truth", "DBB5", 1e-4, 1e-4},
    };
    for (const Case& c : cases) {
        test::ScratchDir dir("id-kinds");
        const std::string m = test::sourcePath(std::string("samples/machines/") + c.machine + ".xml");
        const std::string plan = test::sourcePath(std::string("samples/plans/") + c.plan + ".xml");
        const std::string truth = test::sourcePath(std::string("samples/deviations/") + c.truth + ".csv");
        auto r = test::runCli("simulate --machine " + m + " --plan " + plan + " --deviations " + truth + " --out " +
                              dir.file("t"));
        ASSERT_EQ(r.exitCode, 0) << r.out;
        const MachineModel mm = readMachineXml(m);
        const DeviationSet want = readDeviationCsv(truth, mm);
        for (const std::string method : {"least-squares", "formulas"}) {
            r = test::runCli("identify --machine " + m + " --plan " + plan + " --traces " + dir.file("t") + " --method " +
                             method + " --out " + dir.file(method + ".csv"));
            ASSERT_EQ(r.exitCode, 0) << r.out;
            EXPECT_NE(r.out.find(c.kind), std::string::npos) << r.out;
            const DeviationSet got = readDeviationCsv(dir.file(method + ".csv"), mm);
            for (size_t i = 0; i < mm.deviations.size(); ++i) {
                const DeviationDef& d = mm.deviations[i];
                if (!got.present[i] || d.kind != DeviationKind::Location) continue;
                EXPECT_NEAR(got.isoValue(static_cast<int>(i)), want.isoValue(static_cast<int>(i)),
                            d.isAngle() ? c.tolArcsec * kArcsec : c.tolUm * kUm)
                    << c.plan << " " << method << " " << d.name;
            }
        }
    }
    // A plan with runs of two kinds: least squares only; the formulas are refused with the method that fits.
    test::ScratchDir dir("id-mixed");
    const std::string m = test::sourcePath("samples/machines/table-table-ac.xml");
    test::writeText(dir.file("p.xml"), R"(<plan machine="table-table-ac">
  <rtest name="XYC" ball="150 0 100" steps="36"><hold axis="A" deg="0"/><sweep axis="C" start="0" end="360"/></rtest>
  <dbb5 name="XY" kind="linear" plane="XY" LB="100" ball="0 0 100" step="10"/>
</plan>
)");
    auto r = test::runCli("simulate --machine " + m + " --plan " + dir.file("p.xml") + " --out " + dir.file("t"));
    ASSERT_EQ(r.exitCode, 0) << r.out;
    r = test::runCli("identify --machine " + m + " --plan " + dir.file("p.xml") + " --traces " + dir.file("t") +
                     " --method formulas --out " + dir.file("f.csv"));
    EXPECT_EQ(r.exitCode, 2) << r.out;
    EXPECT_NE(r.out.find("it fits --method least-squares"), std::string::npos) << r.out;
    EXPECT_FALSE(std::filesystem::exists(dir.file("f.csv")));
    r = test::runCli("identify --machine " + m + " --plan " + dir.file("p.xml") + " --traces " + dir.file("t") +
                     " --params EX0C,EY0C,EC0Y --out " + dir.file("l.csv"));
    EXPECT_EQ(r.exitCode, 0) << r.out;
    EXPECT_NE(r.out.find("runs of several kinds"), std::string::npos) << r.out;
    // Outputs that do not belong to the plan's method are refused before anything is written.
    r = test::runCli("identify --machine " + m + " --plan " + dir.file("p.xml") + " --traces " + dir.file("t") +
                     " --params EX0C --angles-out " + dir.file("a.csv") + " --out " + dir.file("n.csv"));
    EXPECT_EQ(r.exitCode, 2) << r.out;
    EXPECT_FALSE(std::filesystem::exists(dir.file("n.csv")));
}

}  // namespace
}  // namespace cnccomp
