#include "cnccomp/inverse_kinematics.hpp"

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

IkResult solveToolPose(const Kinematics& k, const ToolPose& target, const Vec3& tipInToolFrame, const AxisVector& start,
                       const IkOptions& o) {
    IkResult r;
    r.q = start;
    PoseJacobian J;
    Eigen::Matrix<double, 6, 1> res;
    for (r.iterations = 0; r.iterations <= o.maxIterations; ++r.iterations) {
        const ToolPose p = toolPose(k, r.q, tipInToolFrame);
        res.head<3>() = target.tip - p.tip;
        res.tail<3>() = (target.axis - p.axis) * o.axisWeight;
        r.tipError = (target.tip - p.tip).norm();
        r.axisError = (target.axis - p.axis).norm();
        if (r.tipError <= o.tolerance && r.axisError * o.axisWeight <= o.tolerance) {
            r.converged = true;
            break;
        }
        if (r.iterations == o.maxIterations) break;
        toolPoseJacobian(k, r.q, tipInToolFrame, J);
        J.bottomRows<3>() *= o.axisWeight;
        const AxisVector step = J.colPivHouseholderQr().solve(res);
        r.q += step;
        // With fewer than five axes the pose cannot always be met: a vanishing step is the least-squares optimum.
        if (step.norm() <= 1e-13 * (1.0 + r.q.norm())) {
            const ToolPose f = toolPose(k, r.q, tipInToolFrame);
            r.tipError = (target.tip - f.tip).norm();
            r.axisError = (target.axis - f.axis).norm();
            r.converged = true;
            ++r.iterations;
            break;
        }
    }
    return r;
}

}  // namespace cnccomp
