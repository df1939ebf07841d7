// Test planner on the multitasking machine of [MultiTasking]: a plan of at most six runs for the 12 deviations of
// section 5, checked independently by simulating the plan and identifying with the least-squares engine.
#include <gtest/gtest.h>

#include <algorithm>

#include "cnccomp/error.hpp"
#include "cnccomp/identification/eccentricity_observation.hpp"
#include "cnccomp/identification/lsq.hpp"
#include "cnccomp/identification/parameters.hpp"
#include "cnccomp/identification/planner.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "test_support.hpp"

namespace cnccomp {
using namespace cnccomp::identification;
using namespace cnccomp::io;
using namespace cnccomp::measurement;
namespace {

const char* kTwelve = "dxBT dzBT aBT aXB bXB gXB aYZ bYZ dxCZ dyCZ aCZ bCZ";

const DeviationSet& truth() {
    static const DeviationSet d = readDeviationCsv(test::sourcePath("samples/deviations/multitasking-truth.csv"),
                                                   test::multitasking());
    return d;
}

std::vector<BallbarTrace> simulate(const MachineModel& m, std::vector<BallbarRun>& runs, double step) {
    const Kinematics k(m, truth());
    std::vector<BallbarTrace> t;
    for (BallbarRun& r : runs) {
        r.stepDeg = step;
        t.push_back(simulateRun(k, r));
    }
    return t;
}

bool contains(const std::vector<std::string>& v, const std::string& s) {
    return std::find(v.begin(), v.end(), s) != v.end();
}

TEST(PlannerMultitasking, AtMostSixRunsIdentifyTheTwelveFromRawTraces) {
    const MachineModel& m = test::multitasking();
    PlannerOptions o;
    o.identify = parseDeviationList(m, kTwelve);
    const PlanProposal p = proposePlan(m, o);
    ASSERT_TRUE(p.complete);
    EXPECT_LE(p.plan.runs.size(), 6u);
    EXPECT_EQ(p.rank, 12);
    EXPECT_LE(p.conditionNumber, o.targetCondition);
    EXPECT_EQ(p.candidates, 48);  // 12 types × (RB, ZC) pairs; B runs do not depend on RC
    ASSERT_EQ(p.needs.size(), 12u);
    for (const DeviationNeed& n : p.needs) {
        EXPECT_TRUE(n.identified) << n.name;
        EXPECT_FALSE(n.seenBy.empty()) << n.name;
        EXPECT_GT(n.sigmaPerUm, 0.0) << n.name;
        EXPECT_LT(n.sigmaPerUm, 5.0) << n.name;  // µm or arcsec per µm of ΔL noise
    }
    // γXY, not requested: the raw traces of the C runs see it (the XY circle becomes an ellipse).
    ASSERT_EQ(p.others.size(), 1u);
    EXPECT_EQ(p.others[0].alias, "gXY");
    EXPECT_TRUE(p.others[0].identifiedByPlan);
    EXPECT_TRUE(contains(p.others[0].seenByTypes, "C-radial"));
    EXPECT_FALSE(contains(p.others[0].seenByTypes, "B-X"));

    // Independent check: simulate the plan on the truth (γXY = 3 arcsec included) and identify.
    std::vector<BallbarRun> runs = p.plan.runs;
    const auto traces = simulate(m, runs, 5.0);
    const IdentificationResult r = identify(m, ballbarObservations(m, runs, traces));
    EXPECT_EQ(r.report.rank, 13);
    for (const ParameterEstimate& e : r.report.parameters)
        EXPECT_LT(std::abs(e.value - truth().get(e.name)) / e.displayScale(), 1e-3) << e.name;

    // "needs" is true: without a run a deviation needs, the engine reports it unidentified.
    for (const DeviationNeed& n : p.needs) {
        for (const std::string& run : n.needs) {
            std::vector<BallbarRun> fewer;
            std::vector<BallbarTrace> fewerTraces;
            for (size_t i = 0; i < runs.size(); ++i)
                if (runs[i].name != run) {
                    fewer.push_back(runs[i]);
                    fewerTraces.push_back(traces[i]);
                }
            IdentifyOptions io;
            io.deviations = o.identify;
            const IdentificationResult w = identify(m, ballbarObservations(m, fewer, fewerTraces), io);
            EXPECT_TRUE(contains(w.report.unidentified, n.name)) << n.name << " without " << run;
        }
    }
}

TEST(PlannerMultitasking, EccentricitiesNeedTheCXRunForSquarenessXY) {
    // Planning for [MultiTasking]'s closed-form input (circle centres only): six runs still suffice for the twelve, and
    // γXY is seen by a single run type. [MultiTasking] section 4.2 names the Y-direction run; in the exact model with the
    // W-side ball set on the T-side ball it is the X-direction run (see Table3.SquarenessXYShowsInTheCXRunNotTheCYRun).
    const MachineModel& m = test::multitasking();
    PlannerOptions o;
    o.identify = parseDeviationList(m, kTwelve);
    o.observe = "eccentricity";
    const PlanProposal p = proposePlan(m, o);
    ASSERT_TRUE(p.complete);
    EXPECT_LE(p.plan.runs.size(), 6u);
    ASSERT_EQ(p.others.size(), 1u);
    const ExtraAdvice& g = p.others[0];
    EXPECT_EQ(g.name, "EC0Y");
    EXPECT_EQ(g.seenByTypes, std::vector<std::string>{"C-X"});
    EXPECT_FALSE(g.identifiedByPlan);
    ASSERT_FALSE(g.extraRuns.empty());
    // Check the advice: with the first suggested extra run, least squares on eccentricities identifies all 13.
    std::vector<BallbarRun> runs = p.plan.runs;
    IdentifyOptions io;
    io.deviations = parseDeviationList(m, "all");
    {
        const auto traces = simulate(m, runs, 10.0);
        const IdentificationResult r = identify(m, eccentricityObservations(m, runs, traces), io);
        EXPECT_EQ(r.report.rank, 12);  // 13 unknowns from 6 × 2 eccentricity components
        EXPECT_TRUE(contains(r.report.unidentified, "EC0Y"));
    }
    bool added = false;
    for (BallbarTest t : kAllBallbarTests)
        for (double rb : o.RB)
            for (double zc : o.ZC) {
                BallbarRun r;
                r.test = t;
                r.RB = rb;
                r.ZC = zc;
                r.startDeg = rotatesHead(t) ? -180 : 0;
                r.endDeg = rotatesHead(t) ? 180 : 360;
                if (candidateName(r) == g.extraRuns[0] && !added) {
                    r.name = candidateName(r);
                    runs.push_back(r);
                    added = true;
                }
            }
    ASSERT_TRUE(added) << g.extraRuns[0];
    const auto traces = simulate(m, runs, 10.0);
    const IdentificationResult r = identify(m, eccentricityObservations(m, runs, traces), io);
    EXPECT_TRUE(r.report.unidentified.empty());
    // Eccentricities of the exact model differ from the truth by second-order terms only (≈ 0.01 µm, arcsec).
    EXPECT_NEAR(r.deviations.get("gXY"), truth().get("gXY"), 0.05 * kArcsec);
}

TEST(PlannerMultitasking, WrittenPlanReadsBack) {
    const MachineModel& m = test::multitasking();
    PlannerOptions o;
    o.identify = parseDeviationList(m, "gXB,dzBT");
    const PlanProposal p = proposePlan(m, o);
    ASSERT_TRUE(p.complete);
    EXPECT_EQ(p.plan.runs.size(), 2u);  // δzBT is seen in X by B-X/B-Z type runs, γXB in B-Y/B-axial ones
    test::ScratchDir dir("planner");
    writePlanXml(dir.file("p.xml"), p.plan);
    const MeasurementPlan back = readPlanXml(dir.file("p.xml"));
    ASSERT_EQ(back.runs.size(), p.plan.runs.size());
    for (size_t i = 0; i < back.runs.size(); ++i) {
        EXPECT_EQ(back.runs[i].name, p.plan.runs[i].name);
        EXPECT_EQ(back.runs[i].test, p.plan.runs[i].test);
        EXPECT_EQ(back.runs[i].RB, p.plan.runs[i].RB);
        EXPECT_EQ(back.runs[i].stepDeg, 1.0);
    }
    EXPECT_EQ(back.machine, "multitasking");
}

TEST(PlannerMultitasking, ImpossibleRequestIsNamed) {
    // Only B-axis run types: the C-axis location errors cannot be made identifiable.
    const MachineModel& m = test::multitasking();
    PlannerOptions o;
    o.identify = parseDeviationList(m, "dxCZ dyCZ gXB");
    o.types = {BallbarTest::BX, BallbarTest::BY, BallbarTest::BZ};
    const PlanProposal p = proposePlan(m, o);
    EXPECT_FALSE(p.complete);
    EXPECT_EQ(p.rank, 1);
    for (const DeviationNeed& n : p.needs) EXPECT_EQ(n.identified, n.alias == "gXB") << n.name;
}

TEST(PlannerMultitasking, MountingOffsetsAndBadOptions) {
    const MachineModel& m = test::multitasking();
    PlannerOptions o;
    o.identify = parseDeviationList(m, kTwelve);
    o.mounting = "both";  // every run's ball offsets unknown: less can be identified per run
    const PlanProposal p = proposePlan(m, o);
    EXPECT_LT(p.rank, 12);
    EXPECT_FALSE(p.complete);
    o.mounting = "sideways";
    EXPECT_THROW(proposePlan(m, o), ModelError);
    o.mounting = "none";
    o.observe = "guess";
    EXPECT_THROW(proposePlan(m, o), ModelError);
    o.observe = "traces";
    o.identify.clear();
    EXPECT_THROW(proposePlan(m, o), ModelError);
    o.identify = {0};
    o.ZC = {5000};  // every candidate leaves the Z travel
    EXPECT_THROW(proposePlan(m, o), ModelError);
}

}  // namespace
}  // namespace cnccomp
