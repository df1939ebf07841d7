#include "cnccomp/inverse_kinematics.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

namespace cnccomp {

ToolPose toolPose(const Kinematics& k, const AxisVector& q, const Vec3& tipInToolFrame) {
    const Pose wMt = k.workpieceToTool(q);
    return {wMt * tipInToolFrame, wMt.linear() * k.machine().toolDirection};
}

void toolPoseJacobian(const Kinematics& k, const AxisVector& q, const Vec3& tipInToolFrame, PoseJacobian& J) {
    const int n = static_cast<int>(q.size());
    J.resize(6, n);
    const auto joints = k.jointFrames(q);
    const Pose bMw = k.baseToWorkpiece(q);
    const Pose bMt = k.baseToTool(q);
    const Mat3 wRb = bMw.linear().transpose();
    const Vec3 tipB = bMt * tipInToolFrame;
    const Vec3 axisB = bMt.linear() * k.machine().toolDirection;
    J.setZero();
    for (const JointFrame& j : joints) {
        // Tool-side motion moves the tool; workpiece-side motion moves the workpiece, i.e. the tool relative
        // to it the other way. Differentiate in the bed frame, then rotate into the workpiece frame.
        const double sign = j.side == Side::Tool ? 1.0 : -1.0;
        Vec3 dTip, dAxis;
        if (j.rotary) {
            dTip = j.direction.cross(tipB - j.point);
            dAxis = j.direction.cross(axisB);
        } else {
            dTip = j.direction;
            dAxis = Vec3::Zero();
        }
        J.block<3, 1>(0, j.axis) = sign * (wRb * dTip);
        J.block<3, 1>(3, j.axis) = sign * (wRb * dAxis);
    }
}

double rotarySingularValue(const MachineModel& m, const PoseJacobian& J) {
    // Fixed-capacity storage: called once per Gauss–Newton iteration, no allocation.
    using Small = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxAxes, kMaxAxes>;
    int rotary[kMaxAxes], k = 0;
    for (int i = 0; i < m.axisCount(); ++i)
        if (m.axisLink(i).kind == AxisKind::Rotary) rotary[k++] = i;
    if (k == 0) return 1.0;
    Small G(k, k);
    for (int a = 0; a < k; ++a)
        for (int b = 0; b < k; ++b) G(a, b) = J.block<3, 1>(3, rotary[a]).dot(J.block<3, 1>(3, rotary[b]));
    const double lambda = Eigen::SelfAdjointEigenSolver<Small>(G, Eigen::EigenvaluesOnly).eigenvalues()[0];
    return std::sqrt(std::max(lambda, 0.0));
}

/// The pull's weight at the current Jacobian (IkOptions::rotaryRegularization, singularZone).
static double pullWeight(const MachineModel& m, const PoseJacobian& J, const IkOptions& o) {
    if (o.singularZone <= 0) return o.rotaryRegularization;
    // Outside the zone a floor of 1e-4 keeps the system regular (a redundant rotary axis); its share of the axis
    // error is (1e-4 · rotaryRegularization / (axisWeight · σ))², below 1e-8 for the component's values.
    const double s = rotarySingularValue(m, J) / o.singularZone;
    return o.rotaryRegularization * (s >= 1.0 ? 1e-4 : std::max(1.0 - s * s, 1e-4));
}

IkResult solveToolPose(const Kinematics& k, const ToolPose& target, const Vec3& tipInToolFrame, const AxisVector& start,
                       const IkOptions& o) {
    using System = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 6 + kMaxAxes, kMaxAxes>;
    using Rhs = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 6 + kMaxAxes, 1>;
    const MachineModel& m = k.machine();
    const int n = static_cast<int>(start.size());
    IkResult r;
    r.q = start;
    PoseJacobian J;
    System A(6 + n, n);
    Rhs b(6 + n);
    for (r.iterations = 0; r.iterations < o.maxIterations; ++r.iterations) {
        const ToolPose p = toolPose(k, r.q, tipInToolFrame);
        r.tipError = (target.tip - p.tip).norm();
        r.axisError = (target.axis - p.axis).norm();
        toolPoseJacobian(k, r.q, tipInToolFrame, J);
        A.setZero();
        A.topRows<3>() = J.topRows<3>();
        A.middleRows<3>(3) = J.bottomRows<3>() * o.axisWeight;
        b.head<3>() = target.tip - p.tip;
        b.segment<3>(3) = (target.axis - p.axis) * o.axisWeight;
        const double pull = pullWeight(m, J, o);
        for (int i = 0; i < n; ++i) {
            const bool rotary = m.axisLink(i).kind == AxisKind::Rotary;
            A(6 + i, i) = rotary ? pull : 0.0;
            b[6 + i] = rotary ? pull * (start[i] - r.q[i]) : 0.0;
        }
        const AxisVector step = A.colPivHouseholderQr().solve(b);
        r.q += step;
        if (step.norm() <= std::max(1e-13 * (1.0 + r.q.norm()), 0.1 * o.tolerance)) {
            r.converged = true;
            ++r.iterations;
            break;
        }
    }
    // Polish without the pull, so that regular poses meet the axis fully; a polish step that would swing a rotary
    // axis (a singular direction) or does not lower the cost is refused.
    const auto cost = [&](const AxisVector& q) {
        const ToolPose p = toolPose(k, q, tipInToolFrame);
        return (target.tip - p.tip).squaredNorm() + (o.axisWeight * (target.axis - p.axis)).squaredNorm();
    };
    double current = cost(r.q);
    for (int polish = 0; polish < 4 && r.converged && o.polish; ++polish) {
        const ToolPose p = toolPose(k, r.q, tipInToolFrame);
        toolPoseJacobian(k, r.q, tipInToolFrame, J);
        A.setZero();
        A.topRows<3>() = J.topRows<3>();
        A.middleRows<3>(3) = J.bottomRows<3>() * o.axisWeight;
        b.setZero();
        b.head<3>() = target.tip - p.tip;
        b.segment<3>(3) = (target.axis - p.axis) * o.axisWeight;
        const AxisVector step = A.topRows(6).colPivHouseholderQr().solve(b.head<6>());
        double rotaryStep = 0;
        for (int i = 0; i < n; ++i)
            if (m.axisLink(i).kind == AxisKind::Rotary) rotaryStep = std::max(rotaryStep, std::abs(step[i]));
        if (!(rotaryStep < o.rotaryRegularization / o.axisWeight)) break;
        const AxisVector trial = r.q + step;
        const double c = cost(trial);
        if (!(c < current)) break;
        r.q = trial;
        current = c;
    }
    const ToolPose f = toolPose(k, r.q, tipInToolFrame);
    r.tipError = (target.tip - f.tip).norm();
    r.axisError = (target.axis - f.axis).norm();
    return r;
}

}  // namespace cnccomp
