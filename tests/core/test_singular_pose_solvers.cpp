// The singular pose (tool axis parallel to a rotary axis) through the configurations of the inverse solver
// (src/cnccomp/pose_solver.hpp, one damped step): the core's solveToolPose as the controllers' apply models and verify
// use it (IkOptions: constant rotary pull + polish), as the LinuxCNC kinematics component mirrors it
// (kinsSolverOptions: the singular-pose policy with a zone, no polish), and correct's chord Newton
// (postproc/correction: the same policy with its own λ and zone). This test fixes what they share at the
// singular pose: the tip is met, the rotary axis that cannot turn the tool axis stays where it was commanded (no
// swing), and the tool-axis error that no axis can remove is left, the same in all three. Oracle: the exact forward
// kinematics (cnccomp::Kinematics) at each solution.
#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "cnccomp/inverse_kinematics.hpp"
#include "controllers/linuxcnc/kins_component.hpp"
#include "postproc/correction.hpp"
#include "test_support.hpp"

namespace cnccomp {
namespace {

TEST(SingularPose, ToolAxisParallelToCIsHandledAlikeByTheThreeConfigurations) {
    // Multitasking machine at B = 0 (and just off it): the tool axis is parallel to C; the spindle's tilt about X
    // (aBT) cannot be corrected there by any axis.
    const MachineModel& m = test::multitasking();
    DeviationSet d(m);
    d.set("aBT", 6.5 * kArcsec);
    d.set("dxBT", 0.012);
    const Kinematics nominal(m), actual(m, d);
    postproc::Corrector corrector(m, d);
    ASSERT_TRUE((m.fromController(AxisVector::Zero(m.axisCount())).array() == 0.0).all());  // commands = model's
    const int B = m.requireAxis("B"), C = m.requireAxis("C");
    const double L = 100.0;
    const Vec3 tip = nominal.toolPoint(L);
    AxisVector q = AxisVector::Zero(m.axisCount());
    q[m.requireAxis("X")] = 30;
    q[m.requireAxis("Z")] = 150;
    q[C] = 0.4;
    for (double bDeg : {0.0, 1e-4}) {
        SCOPED_TRACE(bDeg);
        q[B] = bDeg * kDeg;
        const ToolPose target = toolPose(nominal, q, tip);
        const IkResult core = solveToolPose(actual, target, tip, q);
        const IkResult kins = solveToolPose(actual, target, tip, q, controllers::linuxcnc::kinsSolverOptions());
        EXPECT_TRUE(kins.converged);
        AxisVector corrected;
        const postproc::SolveResult s = corrector.solve(q, L, q, corrected);
        EXPECT_TRUE(core.converged);
        EXPECT_TRUE(s.converged);
        for (const AxisVector* sol : std::initializer_list<const AxisVector*>{&core.q, &kins.q, &corrected}) {
            const ToolPose got = toolPose(actual, *sol, tip);
            EXPECT_LT((got.tip - target.tip).norm(), 1e-6);         // mm: the slides meet the tip
            EXPECT_LT(std::fabs((*sol)[C] - q[C]), 1e-3);          // rad: C is not swung round
            const double axisError = std::acos(std::clamp(got.axis.dot(target.axis), -1.0, 1.0));
            EXPECT_NEAR(axisError / kArcsec, 6.5, 0.5);           // the uncorrectable tilt is left, in all three
        }
        // The three solutions are one pose to well within the tolerance of correct (1 µm).
        EXPECT_LT((toolPose(actual, kins.q, tip).tip - toolPose(actual, core.q, tip).tip).norm(), 1e-6);
        EXPECT_LT((toolPose(actual, corrected, tip).tip - toolPose(actual, core.q, tip).tip).norm(), 1e-6);
    }
}

// solveToolPose with a singular zone (the component's options, kinsSolverOptions: λ = 10 mm/rad, σ0 = 0.1, no polish)
// uses the one singular-pose policy of pose_solver.hpp: D = λ² Σ φ(σᵢ) vᵢ vᵢᵀ damps only the rotary directions that
// turn the tool axis by less than σ0 rad/rad. On the multi-tasking machine at B = 0 the tool axis is parallel to C
// (σ = 0 for C: damped fully) while B still tilts it in X (σ = 1: not damped), so a B zero error (bXB, tilting the
// axis about Y) is corrected exactly by B and the spindle's squareness about X (aBT) is left; the scalar pull this
// replaced damped B as well and left 1% of bXB's tilt (0.08″). Across the zone C turns smoothly and by at most
// about 1.21·δ/σ0 for the tool-axis error δ (maximum over σ of w²σ/(w²σ² + λ²φ(σ)) with λ = w·σ0, w = axisWeight);
// outside it tip and axis are met exactly. Oracle: the exact forward kinematics at each solution, and the bound
// derived from the policy's formula.
TEST(SingularPose, ZonedPolicyDampsOnlyTheDirectionThatCannotTurnTheToolAxis) {
    const MachineModel& m = test::multitasking();
    DeviationSet d(m);
    d.set("aBT", 6.5 * kArcsec);
    d.set("bXB", 8.0 * kArcsec);
    d.set("dxBT", 0.012);
    const Kinematics nominal(m), actual(m, d);
    const IkOptions ik = controllers::linuxcnc::kinsSolverOptions();
    ASSERT_GT(ik.singularZone, 0.0);
    const int B = m.requireAxis("B"), C = m.requireAxis("C");
    const Vec3 tip = nominal.toolPoint(60.0);
    AxisVector q = AxisVector::Zero(m.axisCount());
    q[m.requireAxis("X")] = 30;
    q[m.requireAxis("Y")] = -12;
    q[m.requireAxis("Z")] = 150;
    q[C] = 0.4;
    const auto solve = [&](double bDeg) {
        q[B] = bDeg * kDeg;
        return solveToolPose(actual, toolPose(nominal, q, tip), tip, q, ik);
    };
    {   // At the singular pose: C stays, B removes the tilt it can remove, the tip is met.
        const IkResult r = solve(0.0);
        ASSERT_TRUE(r.converged);
        const ToolPose target = toolPose(nominal, q, tip), got = toolPose(actual, r.q, tip);
        EXPECT_LT((got.tip - target.tip).norm(), 1e-9);
        PoseJacobian J;
        toolPoseJacobian(actual, r.q, tip, J);
        // B removes bXB, so the tool axis is parallel to C again (σ = 0: C damped fully) and C's fixed point is its
        // command; the iteration stops within 1e-8 rad (0.002″) of it (measured 1.2e-9).
        EXPECT_LT(rotarySingularValue(m, J), 1e-9);
        EXPECT_LT(std::fabs(r.q[C] - q[C]), 1e-8);
        const Vec3 byB = J.block<3, 1>(3, B).normalized();  // the direction in which B turns the tool axis
        EXPECT_LT(std::fabs((got.axis - target.axis).dot(byB)), 1e-9);  // rad: bXB's tilt removed (scalar pull: 4e-7)
        EXPECT_NEAR(std::acos(std::clamp(got.axis.dot(target.axis), -1.0, 1.0)) / kArcsec, 6.5, 0.3);
    }
    // Across the zone, B from −8° to 8° in steps of 0.05°: C corrects at most 1.25·δ/σ0, and between neighbouring
    // poses by at most the formula's slope bound 2.6·δ/σ0² per rad of B (|dσ/dB| ≤ 1); the tip is always met.
    const double s0 = ik.singularZone;
    double previous = 0, worst = 0;
    for (int i = -160; i <= 160; ++i) {
        const double bDeg = 0.05 * i;
        SCOPED_TRACE(bDeg);
        const IkResult r = solve(bDeg);
        ASSERT_TRUE(r.converged);
        const ToolPose target = toolPose(nominal, q, tip), before = toolPose(actual, q, tip);
        const double delta = std::acos(std::clamp(before.axis.dot(target.axis), -1.0, 1.0));
        EXPECT_LT(r.tipError, 1e-9);
        const double dc = r.q[C] - q[C];
        EXPECT_LE(std::fabs(dc), 1.25 * delta / s0);
        if (i > -160) {
            EXPECT_LE(std::fabs(dc - previous), 2.6 * delta / (s0 * s0) * 0.05 * kDeg);
        }
        previous = dc;
        worst = std::max(worst, std::fabs(dc));
    }
    EXPECT_GT(worst, 0.5 * 6.5 * kArcsec / s0);  // C does correct inside the zone, as the formula says
    // Outside the zone nothing is damped: tip and tool axis exact.
    for (double bDeg : {6.0, 10.0, -30.0, 90.0, -179.0 + 10.0}) {
        SCOPED_TRACE(bDeg);
        const IkResult r = solve(bDeg);
        ASSERT_TRUE(r.converged);
        EXPECT_LT(r.tipError, 1e-9);
        EXPECT_LT(r.axisError, 1e-10);
    }
}

}  // namespace
}  // namespace cnccomp
