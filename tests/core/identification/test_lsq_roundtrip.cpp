// Noise-free round trips of the least-squares engine on the multitasking machine of [MultiTasking]: simulate ball-bar
// runs with a known deviation set, identify from the raw ΔL samples, compare with the truth; rank-deficient
// requests are reported by name with their identifiable combinations.
#include <gtest/gtest.h>

#include <algorithm>

#include "cnccomp/error.hpp"
#include "cnccomp/identification/lsq.hpp"
#include "cnccomp/identification/parameters.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "test_support.hpp"

namespace cnccomp {
using namespace cnccomp::identification;
using namespace cnccomp::io;
using namespace cnccomp::measurement;
namespace {

const MeasurementPlan& sixCircles() {
    static const MeasurementPlan p = readPlanXml(test::sourcePath("samples/plans/multitasking-six-circles.xml"));
    return p;
}
const DeviationSet& truth() {
    static const DeviationSet d = readDeviationCsv(test::sourcePath("samples/deviations/multitasking-truth.csv"),
                                                   test::multitasking());
    return d;
}

Observations simulate(const MachineModel& m, const DeviationSet& d, std::vector<BallbarRun> runs, double stepDeg) {
    const Kinematics k(m, d);
    std::vector<BallbarTrace> traces;
    for (BallbarRun& r : runs) {
        r.stepDeg = stepDeg;
        traces.push_back(simulateRun(k, r));
    }
    return ballbarObservations(m, runs, traces);
}

std::vector<BallbarRun> runsNamed(std::initializer_list<const char*> names) {
    std::vector<BallbarRun> out;
    for (const char* n : names)
        for (const BallbarRun& r : sixCircles().runs)
            if (r.name == n) out.push_back(r);
    return out;
}

/// |identified − truth| in µm / arcsec.
double errorDisplay(const ParameterEstimate& p, const DeviationSet& t, const MachineModel& m) {
    const int i = m.deviationIndex(p.name);  // report values are ISO values
    return std::abs(p.value - t.isoValue(i)) / p.displayScale();
}

const Combination* findCombination(const std::vector<Combination>& list, const std::string& text) {
    for (const Combination& c : list)
        if (c.text == text) return &c;
    return nullptr;
}

TEST(LsqRoundTrip, SixCirclesRecoverAllThirteenDeviations) {
    // Raw ΔL samples see more than the eccentricities of [MultiTasking]: γXY (EC0Y) changes the shape of the C-radial
    // trajectories, so all 13 deviations, γXY included, are identifiable from the six runs.
    const MachineModel& m = test::multitasking();
    const IdentificationResult r = identify(m, simulate(m, truth(), sixCircles().runs, 5.0));
    const IdentificationReport& rep = r.report;
    EXPECT_TRUE(rep.converged) << rep.termination;
    EXPECT_EQ(rep.rank, 13);
    EXPECT_EQ(rep.unknowns, 13);
    EXPECT_TRUE(rep.unidentified.empty());
    EXPECT_LT(rep.conditionNumber, 1e3);
    EXPECT_LT(rep.costAfter, 1e-12 * rep.costBefore);
    ASSERT_EQ(rep.parameters.size(), 13u);
    for (const ParameterEstimate& p : rep.parameters) {
        EXPECT_TRUE(p.identified) << p.name;
        EXPECT_LT(errorDisplay(p, truth(), m), 1e-3) << p.name;
    }
    // The output set holds the same values and marks all of them present.
    for (size_t i = 0; i < m.deviations.size(); ++i) {
        EXPECT_TRUE(r.deviations.present[i]);
        EXPECT_NEAR(r.deviations.values[m.deviations[i].offset], truth().values[m.deviations[i].offset], 1e-9);
    }
    for (const RunResidual& rr : rep.runs) {
        EXPECT_GT(rr.rmsBefore, 1e-4) << rr.run;  // the deviations are visible (> 0.1 µm RMS)
        EXPECT_LT(rr.rmsAfter, 1e-9) << rr.run;
    }
}

TEST(LsqRoundTrip, ChosenSubsetWithOthersFixedAtKnownValues) {
    // Identify the four C-axis deviations only; the others are known (the truth) and held fixed.
    const MachineModel& m = test::multitasking();
    IdentifyOptions o;
    o.deviations = parseDeviationList(m, "dxCZ, dyCZ EA0C;bCZ");
    DeviationSet start = truth();
    for (int i : o.deviations) start.values[m.deviations[i].offset] = 0.0;
    o.start = start;
    const IdentificationResult r = identify(m, simulate(m, truth(), sixCircles().runs, 10.0), o);
    ASSERT_EQ(r.report.parameters.size(), 4u);
    EXPECT_EQ(r.report.parameters[0].name, "EX0C");
    for (const ParameterEstimate& p : r.report.parameters) EXPECT_LT(errorDisplay(p, truth(), m), 1e-3) << p.name;
}

TEST(LsqRoundTrip, MountingOffsetsAsNuisanceParameters) {
    // Tool-ball and work-ball mounting offsets of the B runs (estimate-mounting="both") are recovered with the
    // C-axis and squareness deviations they do not confound.
    const MachineModel& m = test::multitasking();
    std::vector<BallbarRun> runs = sixCircles().runs;
    const Vec3 tOff(0.004, -0.003, 0.002), wOff(-0.005, 0.006, 0.003);
    for (BallbarRun& r : runs) {
        r.toolBallOffset = tOff;
        r.workBallOffset = wOff;
    }
    const Observations data = simulate(m, truth(), runs, 5.0);
    for (BallbarRun& r : runs) {  // the identification does not know the offsets of the first two runs
        if (r.name == "B-X" || r.name == "B-Y") {
            r.toolBallOffset = r.workBallOffset = Vec3::Zero();
            r.estimateToolBallOffset = r.estimateWorkBallOffset = true;
        }
    }
    std::vector<BallbarTrace> traces;
    for (const auto& o : data) {
        BallbarTrace t;
        const auto& bo = static_cast<const BallbarObservation&>(*o);
        for (size_t i = 0; i < bo.commands().size(); ++i) t.angleDeg.push_back(bo.run().anglesDeg()[i]);
        t.dL.assign(o->measured().data(), o->measured().data() + o->size());
        traces.push_back(t);
    }
    const IdentificationResult r = identify(m, ballbarObservations(m, runs, traces));
    const IdentificationReport& rep = r.report;
    EXPECT_EQ(rep.unknowns, 13 + 12);
    // Every identified unknown is exact to 0.001 µm / arcsec (the out-of-plane offsets, unobservable to first
    // order, are left at zero and bias the rest by products of a few µm over LB: 1e-4 µm); nuisance offsets of
    // identified directions equal the simulated ones.
    for (size_t i = 0; i < rep.parameters.size(); ++i) {
        const ParameterEstimate& p = rep.parameters[i];
        if (!p.identified) continue;
        if (p.nuisance) {
            const bool tool = p.name.find('T') != std::string::npos;
            const int axis = p.name[p.name.size() - 2] - 'x';
            EXPECT_NEAR(p.value, (tool ? tOff : wOff)[axis], 1e-3 * kUm) << p.name;
        } else {
            EXPECT_LT(errorDisplay(p, truth(), m), 1e-3) << p.name;
        }
    }
    // A tool-ball offset of a B run moves the T-side ball like the offset of the tool spindle in the head
    // (δxBT, δzBT), and offsets across the plane of the run only act at second order: the report says so by name.
    for (const char* n : {"EX0C1", "EZ0C1", "B-X.yT", "B-X.yW", "B-Y.yT"})
        EXPECT_NE(std::find(rep.unidentified.begin(), rep.unidentified.end(), n), rep.unidentified.end()) << n;
    EXPECT_TRUE(findCombination(rep.identifiable, "EX0C1 + B-X.xT"));
    EXPECT_TRUE(findCombination(rep.identifiable, "EZ0C1 + B-X.zT"));
    EXPECT_TRUE(findCombination(rep.unobservable, "B-X.yW"));
    for (const char* n : {"EA0C1", "EC0B", "EC0Y", "EY0C", "EA0C"}) EXPECT_TRUE(rep.parameters[rep.find(n)].identified) << n;
}

TEST(LsqRoundTrip, CAxisOffsetsFromBAxisRunsAreReportedUnidentifiable) {
    // A B-axis run never moves C; the W-side ball is set on the workpiece side, so the C-axis location errors
    // cannot change any ΔL: they are reported unidentified, by name, and left out of the output set.
    const MachineModel& m = test::multitasking();
    IdentifyOptions o;
    o.deviations = parseDeviationList(m, "EX0C EY0C aCZ bCZ dzBT gXB");
    const IdentificationResult r = identify(m, simulate(m, truth(), runsNamed({"B-X", "B-Y"}), 10.0), o);
    const IdentificationReport& rep = r.report;
    EXPECT_EQ(rep.rank, 2);
    EXPECT_EQ(rep.unidentified, (std::vector<std::string>{"EX0C", "EY0C", "EA0C", "EB0C"}));
    for (const char* n : {"EX0C", "EY0C", "EA0C", "EB0C"}) {
        const ParameterEstimate& p = rep.parameters[rep.find(n)];
        EXPECT_FALSE(p.identified);
        EXPECT_TRUE(std::isnan(p.stddev));
        EXPECT_FALSE(r.deviations.present[m.deviationIndex(n)]) << n;
        EXPECT_TRUE(findCombination(rep.unobservable, n)) << n;  // each alone is a blind direction
    }
    EXPECT_TRUE(rep.identifiable.empty());  // nothing about them can be said
    // The B-run deviations in the same request are still identified (zero residual in their directions).
    for (const char* n : {"dzBT", "gXB"}) {
        const ParameterEstimate& p = rep.parameters[rep.find(n)];
        EXPECT_TRUE(p.identified) << n;
        EXPECT_TRUE(r.deviations.present[m.deviationIndex(n)]) << n;
    }
    EXPECT_FALSE(rep.warnings.empty());
}

TEST(LsqRoundTrip, ConfoundedDeviationsAreReportedAsNamedCombinations) {
    // From B-X and B-Y alone, the X offset of the spindle (δxBT) and the tilts about Y of B (βXB) and of the
    // Y/X slides (βYZ) only enter as δxBT − RB·(βXB + βYZ), RB = 360 mm the tool length; αXB and αYZ only as their sum.
    const MachineModel& m = test::multitasking();
    IdentifyOptions o;
    o.deviations = parseDeviationList(m, "dxBT dzBT aXB bXB gXB aYZ bYZ");
    const IdentificationResult r = identify(m, simulate(m, truth(), runsNamed({"B-X", "B-Y"}), 10.0), o);
    const IdentificationReport& rep = r.report;
    EXPECT_EQ(rep.rank, 4);
    // In ISO names (EB0Z = −βYZ, EA0Z = −αYZ on this machine): δxBT − RB·(βXB + βYZ) = EX0C1 − 360·EB0B + 360·EB0Z.
    const Combination* c = findCombination(rep.identifiable, "EX0C1 - 360·EB0B + 360·EB0Z");
    ASSERT_TRUE(c) << (rep.identifiable.empty() ? "" : rep.identifiable[0].text);
    const double expect = truth().get("dxBT") - 360.0 * (truth().get("bXB") + truth().get("bYZ"));
    EXPECT_NEAR(c->value, expect, 1e-3 * kUm);
    const Combination* a = findCombination(rep.identifiable, "EA0B - EA0Z");
    ASSERT_TRUE(a);
    EXPECT_NEAR(a->value, truth().get("aXB") + truth().get("aYZ"), 1e-3 * kArcsec);
    for (const char* n : {"EX0C1", "EA0B", "EB0B", "EA0Z", "EB0Z"})
        EXPECT_NE(std::find(rep.unidentified.begin(), rep.unidentified.end(), n), rep.unidentified.end()) << n;
    // δzBT and γXB are identified exactly despite the confounded rest (products of small errors aside).
    for (const char* n : {"dzBT", "gXB"}) EXPECT_LT(errorDisplay(rep.parameters[rep.find(n)], truth(), m), 1e-3) << n;
}

TEST(LsqRoundTrip, NloptSolverWithBounds) {
    const MachineModel& m = test::multitasking();
    const Observations obs = simulate(m, truth(), sixCircles().runs, 10.0);
    IdentifyOptions o;
    o.deviations = parseDeviationList(m, "all");
    o.solver = {SolverKind::Nlopt, "LD_SLSQP"};
    o.maxIterations = 20;
    const IdentificationResult r = identify(m, obs, o);
    EXPECT_EQ(r.report.solver, "nlopt:LD_SLSQP");
    for (const ParameterEstimate& p : r.report.parameters) EXPECT_LT(errorDisplay(p, truth(), m), 1e-3) << p.name;
    // A bound below the truth holds the estimate on the bound.
    o.bounds = {{"dxBT", -20 * kUm, 10 * kUm}};
    const IdentificationResult b = identify(m, obs, o);
    EXPECT_NEAR(b.report.parameters[b.report.find("dxBT")].value, 10 * kUm, 1e-6 * kUm);
    EXPECT_GT(b.report.costAfter, 1e-3);
    // Unknown algorithm and bounds with the unbounded solver are errors.
    o.solver = {SolverKind::Nlopt, "NO_SUCH_THING"};
    EXPECT_THROW(identify(m, obs, o), ModelError);
    o.solver = {};
    EXPECT_THROW(identify(m, obs, o), ModelError);
    // An algorithm given to Levenberg-Marquardt is refused (solver names as text are parsed by the application
    // layer's options: tests/app/test_identify_facade.cpp).
    o.bounds.clear();
    o.solver = {SolverKind::LevenbergMarquardt, "LD_SLSQP"};
    EXPECT_THROW(identify(m, obs, o), ModelError);
}

TEST(LsqRoundTrip, BadRequestsThrow) {
    const MachineModel& m = test::multitasking();
    EXPECT_THROW(parseDeviationList(m, "EX0C, EQ9Z"), ModelError);
    EXPECT_THROW(parseDeviationList(m, " , "), ModelError);
    EXPECT_THROW(identify(m, Observations{}), ModelError);
    BallbarTrace t{{0.0, 10.0}, {0.0}};
    EXPECT_THROW(BallbarObservation(m, sixCircles().runs[2], t), ModelError);  // size mismatch
    t.dL = {0.0, std::nan("")};
    EXPECT_THROW(BallbarObservation(m, sixCircles().runs[2], t), ModelError);  // NaN sample
    BallbarRun far = sixCircles().runs[2];
    far.ZC = 5000;  // Z beyond its travel
    t.dL = {0.0, 0.0};
    EXPECT_THROW(BallbarObservation(m, far, t), ModelError);
}

}  // namespace
}  // namespace cnccomp
