// Tool-pose Jacobian against central finite differences; inverse kinematics round trips.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "cnccomp/inverse_kinematics.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "test_support.hpp"

namespace cnccomp {
using namespace cnccomp::io;
namespace {

AxisVector somePose(const MachineModel& m, int seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-1, 1);
    AxisVector q(m.axisCount());
    for (int i = 0; i < m.axisCount(); ++i) {
        const Link& l = m.axisLink(i);
        q[i] = l.kind == AxisKind::Rotary ? u(rng) * 1.2 : u(rng) * 200.0 + (m.axisNames[i] == "Z" ? 500 : 0);
    }
    return q;
}

class PerMachine : public ::testing::TestWithParam<const char*> {};

TEST_P(PerMachine, JacobianMatchesFiniteDifferences) {
    const MachineModel m = readMachineXml(test::sourcePath(std::string("samples/machines/") + GetParam() + ".xml"));
    DeviationSet d(m);
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> u(-1, 1);
    for (const auto& def : m.deviations)
        if (def.kind == DeviationKind::Location) d.set(def.name, def.isAngle() ? u(rng) * 50 * kArcsec : u(rng) * 0.03);
    const Kinematics k(m, d);
    const Vec3 tip = k.toolPoint(150.0);
    for (int trial = 0; trial < 5; ++trial) {
        const AxisVector q = somePose(m, trial);
        PoseJacobian J;
        toolPoseJacobian(k, q, tip, J);
        for (int i = 0; i < m.axisCount(); ++i) {
            const double h = 1e-6;
            AxisVector qp = q, qm = q;
            qp[i] += h;
            qm[i] -= h;
            const ToolPose a = toolPose(k, qp, tip), b = toolPose(k, qm, tip);
            Eigen::Matrix<double, 6, 1> fd;
            fd << (a.tip - b.tip) / (2 * h), (a.axis - b.axis) / (2 * h);
            EXPECT_NEAR((J.col(i) - fd).norm(), 0.0, 1e-6 * (1 + fd.norm())) << GetParam() << " axis " << m.axisNames[i];
        }
    }
}

TEST_P(PerMachine, InverseRecoversCommandsOnErroneousMachine) {
    const MachineModel m = readMachineXml(test::sourcePath(std::string("samples/machines/") + GetParam() + ".xml"));
    DeviationSet d(m);
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> u(-1, 1);
    for (const auto& def : m.deviations)
        if (def.kind == DeviationKind::Location) d.set(def.name, def.isAngle() ? u(rng) * 50 * kArcsec : u(rng) * 0.03);
    const Kinematics nominal(m), actual(m, d);
    const Vec3 tip = nominal.toolPoint(150.0);
    for (int trial = 0; trial < 5; ++trial) {
        const AxisVector q = somePose(m, 10 + trial);
        const ToolPose target = toolPose(nominal, q, tip);
        const IkResult r = solveToolPose(actual, target, tip, q);
        ASSERT_TRUE(r.converged) << GetParam() << " trial " << trial << " tip error " << r.tipError;
        const ToolPose got = toolPose(actual, r.q, tip);
        EXPECT_LT((got.tip - target.tip).norm(), 1e-8);
        // A four-axis machine cannot always match the axis; five axes must.
        if (m.axisCount() >= 5) {
            EXPECT_LT((got.axis - target.axis).norm(), 1e-11);
        }
        EXPECT_LT(r.iterations, 8);
    }
}

TEST(InverseKinematics, SingularPoseOfMillTurnKeepsCAndMeetsTheTip) {
    // B = 0: the tool axis is parallel to C. A tilt of the spindle (aBT) cannot be undone by the axes; the solver
    // must meet the tip exactly and leave C where it was commanded.
    const MachineModel& m = test::multitasking();
    DeviationSet d(m);
    d.set("aBT", 20 * kArcsec);
    d.set("dxCZ", 0.015);
    d.set("aCZ", 10 * kArcsec);
    const Kinematics nominal(m), actual(m, d);
    const Vec3 tip = nominal.toolPoint(200.0);
    for (double c : {0.0, 0.7, 2.0}) {
        AxisVector q = AxisVector::Zero(m.axisCount());
        q[m.requireAxis("X")] = 40;
        q[m.requireAxis("Z")] = 500;
        q[m.requireAxis("C")] = c;
        const IkResult r = solveToolPose(actual, toolPose(nominal, q, tip), tip, q);
        EXPECT_TRUE(r.converged);
        EXPECT_LT(r.tipError, 1e-9);
        EXPECT_NEAR(r.q[m.requireAxis("C")], c, 1e-4);
    }
}

TEST(InverseKinematics, ANaNStartOrTargetIsNoConvergence) {
    // The solver's contract: converged means the iteration settled on finite commands. A NaN in the start or the
    // target must come back as not converged, with or without the singular zone (the LinuxCNC component's options).
    // (A normal matrix that cannot be factorised now also ends the iteration unconverged, instead of a zero step taken
    // for a settled one; with the rotary damping that matrix is positive definite on every sample, so no test reaches
    // that branch: it is defensive.) Oracle: the contract, on both policies.
    const MachineModel& m = test::multitasking();
    const Kinematics k(m);
    const Vec3 tip = k.toolPoint(200.0);
    AxisVector q = AxisVector::Zero(m.axisCount());
    q[m.requireAxis("X")] = 40;
    q[m.requireAxis("Z")] = 500;
    q[m.requireAxis("B")] = 0.5;
    const ToolPose target = toolPose(k, q, tip);
    AxisVector start = q;
    start[m.requireAxis("B")] = std::nan("");
    for (double zone : {0.0, 0.1}) {
        IkOptions o;
        o.singularZone = zone;
        const IkResult r = solveToolPose(k, target, tip, start, o);
        EXPECT_FALSE(r.converged) << "zone " << zone;
        EXPECT_FALSE(r.tipError < 1e-6) << "zone " << zone;
        ToolPose bad = target;
        bad.tip.x() = std::nan("");
        EXPECT_FALSE(solveToolPose(k, bad, tip, q, o).converged) << "zone " << zone;
    }
    // The same start without the NaN converges: the refusal is the NaN's, not the pose's.
    start[m.requireAxis("B")] = 0.45;
    EXPECT_TRUE(solveToolPose(k, target, tip, start).converged);
}

INSTANTIATE_TEST_SUITE_P(SampleMachines, PerMachine, ::testing::Values("multitasking", "tilting-head-b", "table-table-ac"));

}  // namespace
}  // namespace cnccomp
