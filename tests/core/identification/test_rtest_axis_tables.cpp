// [RotaryTableModel]: the six kinematic errors of A and C of the cradle as functions of angle. The small-angle model of
// eq. (1)–(7) against the exact kinematics, the per-angle solution from R-test runs with three balls, and the
// least-squares equivalent on the component-error tables with the gauge (C errors zero at C = 0).
#include <gtest/gtest.h>

#include <cmath>

#include "cnccomp/error.hpp"
#include "cnccomp/identification/rtest_axis_tables.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "rtest_fixture.hpp"
#include "test_support.hpp"

namespace cnccomp {
using namespace cnccomp::identification;
using namespace cnccomp::measurement;
namespace {

const MachineModel& tableTable() { return test::sampleMachine("table-table-ac"); }

using Fixture = test::RtestFixture;

const Fixture& kinematicTables() {
    static const Fixture f = test::makeRtestFixture("table-table-ac", "table-table-ac-kinematic", "table-table-ac-kinematic");
    return f;
}

SixErrors truthAt(const DeviationSet& t, const std::string& axis, double rad) {
    SixErrors e;
    const char* c[] = {"EX", "EY", "EZ", "EA", "EB", "EC"};
    for (int i = 0; i < 6; ++i) {
        const DeviationDef& d = t.machine().deviations[t.require(c[i] + axis)];
        const double v = d.basis.evaluate(rad, t.values.data() + d.offset, axis == "C");
        (i < 3 ? e.delta : e.xi)[i % 3] = v;
    }
    return e;
}

/// Largest table difference (µm, arcsec) over the twelve tables.
std::pair<double, double> worst(const DeviationSet& est, const DeviationSet& truth) {
    double um = 0, as = 0;
    for (const char* n : {"EXA", "EYA", "EZA", "EAA", "EBA", "ECA", "EXC", "EYC", "EZC", "EAC", "EBC", "ECC"}) {
        const DeviationDef& d = truth.machine().deviations[truth.require(n)];
        EXPECT_TRUE(est.present[truth.require(n)]) << n;
        for (int k = 0; k < d.size(); ++k) {
            const double e = std::abs(est.values[d.offset + k] - truth.values[d.offset + k]);
            (d.isAngle() ? as : um) = std::max(d.isAngle() ? as : um, e / (d.isAngle() ? kArcsec : kUm));
        }
    }
    return {um, as};
}

TEST(RtestAxisTables, SmallAngleModelMatchesExactKinematics) {
    const MachineModel& m = tableTable();
    const DeviationSet& t = kinematicTables().truth;
    const Kinematics k(m, t);
    const Vec3 w(80, -40, 60);
    double worstDiff = 0;
    for (double a : {-75.0, -20.0, 0.0, 45.0, 90.0})
        for (double c : {0.0, 50.0, 200.0, 315.0}) {
            AxisVector q = AxisVector::Zero(m.axisCount());
            q[m.requireAxis("A")] = a * kDeg;
            q[m.requireAxis("C")] = c * kDeg;
            const Vec3 exact = k.baseToWorkpiece(q) * w;
            const Vec3 small = cradleSmallAngle(Vec3::UnitX(), a * kDeg, truthAt(t, "A", a * kDeg), Vec3::UnitZ(), c * kDeg,
                                                truthAt(t, "C", c * kDeg), w);
            worstDiff = std::max(worstDiff, (exact - small).norm());
            // The errors matter: far above the small-angle residual.
            const Vec3 nominal = Kinematics(m).baseToWorkpiece(q) * w;
            EXPECT_GT((exact - nominal).norm(), 1 * kUm);
        }
    std::printf("[ RotaryTableModel ] eq. (1)-(7) vs exact kinematics: %.2e um\n", worstDiff / kUm);
    EXPECT_LT(worstDiff, 1e-3 * kUm);  // second order: |ξ|²·|W| ≈ 1e-4 µm here
}

TEST(RtestAxisTables, PerAngleFormulasRecoverTheTables) {
    const MachineModel& m = tableTable();
    const Fixture& f = kinematicTables();
    // Each axis on its own: the C sweep at A = 0 also sees A's errors at A = 0 and gives them to C.
    const AxisErrors a = cradleAxisErrors(m, "A", f.plan.rtestRuns, f.traces);
    const AxisErrors c = cradleAxisErrors(m, "C", f.plan.rtestRuns, f.traces);
    EXPECT_EQ(a.samples.size(), 13u);
    EXPECT_EQ(c.samples.size(), 12u);
    for (const auto& s : a.samples) EXPECT_EQ(s.balls, 3);
    const auto [um0, as0] = worst(cradleDeviations(m, {a, c}), f.truth);
    // A first, then C with A's effect removed.
    std::vector<AxisErrors> perAngle;
    const DeviationSet d = cradleTablesPerAngle(m, "A", "C", f.plan.rtestRuns, f.traces, &perAngle);
    ASSERT_EQ(perAngle.size(), 2u);
    const auto [um, as] = worst(d, f.truth);
    std::printf("[ RotaryTableModel ] per-angle eq. (1)-(7): axes alone %.4f um, %.4f arcsec; A then C %.5f um, %.5f arcsec\n",
                um0, as0, um, as);
    // Documented tolerance of the small-angle per-angle solve (second-order terms |ξ|·|δ| and |ξ|²·|p|).
    EXPECT_LT(um, 0.002);
    EXPECT_LT(as, 0.01);
    EXPECT_GT(um0, 0.1);
}

TEST(RtestAxisTables, LeastSquaresRecoversTheTablesExactly) {
    const MachineModel& m = tableTable();
    const Fixture& f = kinematicTables();
    const CradleLsq r = cradleLeastSquares(m, "A", "C", f.plan.rtestRuns, f.traces);
    const auto [um, as] = worst(r.deviations, f.truth);
    std::printf("[ RotaryTableModel ] least squares + gauge: worst %.2e um, %.2e arcsec; %zu unobservable directions\n", um, as,
                r.report.unobservable.size());
    EXPECT_LT(um, 0.001);
    EXPECT_LT(as, 0.001);
    EXPECT_EQ(r.report.unobservable.size(), 6u);  // the constant transform between the A and C frames
}

TEST(RtestAxisTables, CollinearBallsAreRefused) {
    const MachineModel& m = tableTable();
    const Fixture& f = kinematicTables();
    std::vector<RtestRun> runs(f.plan.rtestRuns.begin(), f.plan.rtestRuns.begin() + 2);
    std::vector<RtestTrace> traces(f.traces.begin(), f.traces.begin() + 2);
    EXPECT_THROW(cradleAxisErrors(m, "C", runs, traces), ModelError);
    EXPECT_THROW(cradleAxisErrors(m, "X", runs, traces), ModelError);
}

}  // namespace
}  // namespace cnccomp
