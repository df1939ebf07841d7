#include "cnccomp/inverse_kinematics.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

#include "cnccomp/pose_solver.hpp"

namespace cnccomp {

ToolPose toolPose(const Kinematics& k, const AxisVector& q, const Vec3& tipInToolFrame) {
    const Pose wMt = k.workpieceToTool(q);
    return {wMt * tipInToolFrame, wMt.linear() * k.machine().toolDirection};
}

void toolPoseJacobian(const Kinematics& k, const AxisVector& q, const Vec3& tipInToolFrame, PoseJacobian& J) {
    const int n = static_cast<int>(q.size());
    J.resize(6, n);
    JointFrames joints;  // both chains' frames and joint lines in one walk each
    const Frame bMw = k.model().chainFrame(Side::Workpiece, q, &joints);
    const Frame bMt = k.model().chainFrame(Side::Tool, q, &joints);
    const Mat3 wRb = bMw.R.transpose();
    const Vec3 tipB = bMt.R * tipInToolFrame + bMt.t;
    const Vec3 axisB = bMt.R * k.machine().toolDirection;
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
    AxisConditioning c;  // fixed-capacity storage: called once per Gauss–Newton iteration, no allocation
    c.compute(J, rotaryAxes(m), 1.0, false);
    return c.smallestSingularValue();
}

IkResult solveToolPose(const Kinematics& k, const ToolPose& target, const Vec3& tipInToolFrame, const AxisVector& start,
                       const IkOptions& o) {
    const MachineModel& m = k.machine();
    const int n = static_cast<int>(start.size());
    const uint32_t all = n >= 32 ? ~0u : (1u << n) - 1u, rotary = rotaryAxes(m, all);
    IkResult r;
    r.q = start;
    PoseJacobian J;
    Eigen::Matrix<double, 6, 1> b;
    SmallMatrix JtJ, D;
    DampedNormalFactor normal;
    AxisConditioning cond;
    AxisVector step(n), offset(n);
    // The singular-pose policy (pose_solver.hpp): D = λ² Σ φ(σᵢ) vᵢ vᵢᵀ over the rotary axes, λ = rotaryRegularization,
    // σ0 = singularZone; without a zone φ ≡ 1 (the constant pull λ² I), which needs no decomposition.
    const SingularPosePolicy policy{o.rotaryRegularization, o.singularZone};
    const bool zone = o.singularZone > 0;
    if (!zone) {
        cond.k = 0;
        for (int i = 0; i < n; ++i)
            if (rotary & (1u << i)) cond.axes[cond.k++] = i;
    }
    // The weighted residual and Jacobian at r.q (tool-axis rows × axisWeight) and JᵀJ; with a zone the conditioning
    // of the tool axis over the rotary axes (unweighted rows: σ in rad/rad).
    const auto linearise = [&]() {
        const ToolPose p = toolPose(k, r.q, tipInToolFrame);
        b.head<3>() = target.tip - p.tip;
        b.tail<3>() = (target.axis - p.axis) * o.axisWeight;
        toolPoseJacobian(k, r.q, tipInToolFrame, J);
        if (zone) cond.compute(J, rotary, 1.0, true);
        J.bottomRows<3>() *= o.axisWeight;
        normalMatrix(J, JtJ);
    };
    for (r.iterations = 0; r.iterations < o.maxIterations; ++r.iterations) {
        linearise();
        r.tipError = b.head<3>().norm();
        r.axisError = b.tail<3>().norm() / o.axisWeight;
        // Outside the zone nothing is damped, and no floor is needed: there every rotary direction turns the tool
        // axis by at least σ0, so JᵀJ is regular wherever the slides place the tip; a rotary direction that cannot
        // turn the tool axis (σ = 0) is damped fully (φ = 1).
        const bool damped = singularDamping(policy, cond, n, D);
        offset = r.q - start;
        // A normal matrix that cannot be factorised (a NaN in J) gives no step: not converged, never a zero step
        // taken for a settled one.
        if (!normal.factor(J, JtJ, damped ? &D : nullptr, all, 0.0)) break;
        normal.step(b, damped ? &D : nullptr, offset, all, step);
        r.q += step;
        if (step.norm() <= std::max(1e-13 * (1.0 + r.q.norm()), 0.1 * o.tolerance)) {
            r.converged = true;
            ++r.iterations;
            break;
        }
    }
    // Polish without the pull, so that regular poses meet the axis fully; a polish step that would swing a rotary
    // axis (a singular direction), that the undamped normal matrix cannot give (singular) or that does not lower the
    // cost is refused.
    const auto cost = [&](const AxisVector& q) {
        const ToolPose p = toolPose(k, q, tipInToolFrame);
        return (target.tip - p.tip).squaredNorm() + (o.axisWeight * (target.axis - p.axis)).squaredNorm();
    };
    double current = cost(r.q);
    for (int polish = 0; polish < 4 && r.converged && o.polish; ++polish) {
        linearise();
        if (!normal.factor(J, JtJ, nullptr, all, 0.0)) break;
        normal.step(b, nullptr, offset, all, step);
        double rotaryStep = 0;
        for (int i = 0; i < n; ++i)
            if (rotary & (1u << i)) rotaryStep = std::max(rotaryStep, std::abs(step[i]));
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
