// The singular pose (tool axis parallel to a rotary axis) through the configurations of the inverse solver
// (src/cnccomp/pose_solver.hpp, one damped step): the core's solveToolPose as the controllers' apply models and verify
// use it (IkOptions: constant rotary pull + polish), as the LinuxCNC kinematics component mirrors it
// (kinsSolverOptions: pull inside the singular zone only, no polish), and correct's chord Newton (postproc/correction:
// the singular-pose policy's damping in the ill-conditioned directions). This test fixes what they share at the
// singular pose: the tip is met, the rotary axis that cannot turn the tool axis stays where it was commanded (no
// swing), and the tool-axis error that no axis can remove is left, the same in all three. Oracle: the exact forward
// kinematics (cnccomp::Kinematics) at each solution.
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

}  // namespace
}  // namespace cnccomp
