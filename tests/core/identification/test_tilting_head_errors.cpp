// [FanWuLi]: the tilting head B from absolute ball-bar runs in Y, X and Z patterns with two tool lengths.
// Eq. (4), (13), (20) checked against the exact simulation for single errors; eq. (7), (9), (16), (21) and the
// least-squares equivalent recover the truth of samples/deviations/tilting-head-b-truth.csv.
#include <gtest/gtest.h>

#include <cmath>

#include "cnccomp/error.hpp"
#include "cnccomp/identification/tilting_head_errors.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "test_support.hpp"

namespace cnccomp {
using namespace cnccomp::identification;
using namespace cnccomp::io;
using namespace cnccomp::measurement;
namespace {

const MachineModel& head() {
    static const MachineModel m = readMachineXml(test::sourcePath("samples/machines/tilting-head-b.xml"));
    return m;
}

struct Fixture {
    MeasurementPlan plan;
    DeviationSet truth;
    std::vector<BallbarTrace> traces;
};

const Fixture& headPatterns() {
    static const Fixture f = [] {
        const MachineModel& m = head();
        Fixture x{readPlanXml(test::sourcePath("samples/plans/tilting-head-b-patterns.xml")),
                  readDeviationCsv(test::sourcePath("samples/deviations/tilting-head-b-truth.csv"), m), {}};
        const Kinematics k(m, x.truth);
        for (const BallbarRun& r : x.plan.absoluteRuns) x.traces.push_back(simulateAbsoluteRun(k, r));
        return x;
    }();
    return f;
}

/// Truth of a B component error at an angle (deg), internal units.
double truthAt(const DeviationSet& t, const std::string& name, double deg) {
    const DeviationDef& d = t.machine().deviations[t.require(name)];
    return d.basis.evaluate(deg * kDeg, t.values.data() + d.offset, false);
}

TEST(TiltingHeadErrors, FirstOrderPatternEquationsHold) {
    // One error at a time: eq. (4) (Y pattern), (13) (X), (20) (Z) against the exact absolute ΔL.
    const MachineModel& m = head();
    const double L = 250, B = 37 * kDeg, c = std::cos(B), s = std::sin(B);
    const auto dL = [&](const DeviationSet& d, BallbarTest t) {
        BallbarRun r;
        r.test = t;
        r.LB = 100;
        r.RB = L;
        r.ZC = 0;
        r.startDeg = r.endDeg = 37;
        return simulateAbsoluteRun(Kinematics(m, d), r).dL[0];
    };
    const double e = 10 * kArcsec, u = 5 * kUm;
    const auto withTable = [&](const std::string& name, double v) {
        DeviationSet d(m);
        const DeviationDef& def = m.deviations[d.require(name)];
        for (int k = 0; k < def.size(); ++k) d.values[def.offset + k] = v;  // constant over B
        return d;
    };
    DeviationSet d(m);
    d.set("EA0B", e);  // εBz
    EXPECT_NEAR(dL(d, BallbarTest::BY), L * e * c, 1e-3 * kUm);
    d = DeviationSet(m);
    d.set("EC0B", e);  // εxB
    EXPECT_NEAR(dL(d, BallbarTest::BY), -L * e * s, 1e-3 * kUm);
    EXPECT_NEAR(dL(withTable("EAB", e), BallbarTest::BY), L * e, 1e-3 * kUm);
    EXPECT_NEAR(dL(withTable("EYB", u), BallbarTest::BY), u, 1e-3 * kUm);
    EXPECT_NEAR(dL(withTable("EBB", e), BallbarTest::BX), -L * c * e, 1e-3 * kUm);  // the sign (15) gives
    EXPECT_NEAR(dL(withTable("EXB", u), BallbarTest::BX), c * u, 1e-3 * kUm);
    EXPECT_NEAR(dL(withTable("EZB", u), BallbarTest::BX), s * u, 1e-3 * kUm);
    EXPECT_NEAR(dL(withTable("EBB", e), BallbarTest::BZ), L * s * e, 1e-3 * kUm);
    EXPECT_NEAR(dL(withTable("EXB", u), BallbarTest::BZ), -s * u, 1e-3 * kUm);
    EXPECT_NEAR(dL(withTable("EZB", u), BallbarTest::BZ), c * u, 1e-3 * kUm);
}

TEST(TiltingHeadErrors, FormulasRecoverTheHeadErrorsAtEveryAngle) {
    const Fixture& f = headPatterns();
    const TiltingHeadResult r = tiltingHeadFormulas(f.plan.absoluteRuns, f.traces);
    ASSERT_EQ(r.angles.size(), 17u);
    double um = 0, as = std::max(std::abs(r.exB - f.truth.get("exB")), std::abs(r.eBz - f.truth.get("eBz"))) / kArcsec;
    for (const TiltingHeadAngle& h : r.angles) {
        const double B = h.angleDeg;
        for (auto [v, n] : {std::pair{h.dx, "EXB"}, {h.dy, "EYB"}, {h.dz, "EZB"}})
            um = std::max(um, std::abs(v - truthAt(f.truth, n, B)) / kUm);
        for (auto [v, n] : {std::pair{h.ex, "EAB"}, {h.ey, "EBB"}})
            as = std::max(as, std::abs(v - truthAt(f.truth, n, B)) / kArcsec);
    }
    std::printf("[ FanWuLi ] eq. (7), (9), (16), (21): worst %.5f um, %.5f arcsec over 17 angles\n", um, as);
    // Documented tolerance of the first-order formulas (second-order terms, amplified by L2/(L2 − L1) = 3).
    EXPECT_LT(um, 0.005);
    EXPECT_LT(as, 0.005);
    // As a deviation set on the machine's tables.
    const DeviationSet d = tiltingHeadDeviations(head(), r);
    EXPECT_NEAR(d.get("exB"), r.exB, 0);
    const DeviationDef& ey = head().deviations[d.require("EBB")];
    EXPECT_NEAR(d.values[ey.offset + 8], r.angles[8].ey, 1e-15);  // node 0 deg
}

TEST(TiltingHeadErrors, LeastSquaresRecoversTheTruthExactly) {
    const Fixture& f = headPatterns();
    const TiltingHeadLsq r = tiltingHeadLeastSquares(head(), f.plan.absoluteRuns, f.traces);
    EXPECT_TRUE(r.engine.report.unidentified.empty());
    double um = 0, as = 0;
    for (const char* n : {"EXB", "EYB", "EZB", "EAB", "EBB", "EA0B", "EC0B"}) {
        const DeviationDef& d = head().deviations[f.truth.require(n)];
        for (int k = 0; k < d.size(); ++k) {
            const double e = std::abs(r.deviations.values[d.offset + k] - f.truth.values[d.offset + k]);
            (d.isAngle() ? as : um) = std::max(d.isAngle() ? as : um, e / (d.isAngle() ? kArcsec : kUm));
        }
        EXPECT_TRUE(r.deviations.present[f.truth.require(n)]) << n;
    }
    std::printf("[ FanWuLi ] least squares + gauge of eq. (9): worst %.2e um, %.2e arcsec\n", um, as);
    EXPECT_LT(um, 0.001);
    EXPECT_LT(as, 0.001);
    // Before the gauge split the engine's εx(B) carries Q(B) = εBz cos B − εxB sin B + εx(B) (eq. (4)).
    const DeviationDef& ex = head().deviations[f.truth.require("EAB")];
    const double B = 90 * kDeg;
    EXPECT_NEAR(r.engine.deviations.values[ex.offset + 14],
                f.truth.get("EA0B") * std::cos(B) - f.truth.get("EC0B") * std::sin(B) + truthAt(f.truth, "EAB", 90),
                0.001 * kArcsec);
}

TEST(TiltingHeadErrors, MissingPatternIsNamed) {
    const Fixture& f = headPatterns();
    std::vector<BallbarRun> runs(f.plan.absoluteRuns.begin(), f.plan.absoluteRuns.begin() + 4);
    std::vector<BallbarTrace> traces(f.traces.begin(), f.traces.begin() + 4);
    try {
        tiltingHeadFormulas(runs, traces);
        ADD_FAILURE() << "expected a ModelError";
    } catch (const ModelError& e) {
        EXPECT_NE(std::string(e.what()).find("B-Z"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace cnccomp
