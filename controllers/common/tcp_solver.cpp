#include "controllers/common/tcp_solver.hpp"

#include <Eigen/Eigenvalues>

namespace cnccomp::controllers {

AxisVector compensatedCommands(const Kinematics& actual, const ToolPose& target, const Vec3& tip, const AxisVector& start,
                               int iterations, double axisWeight) {
    using Square = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxAxes, kMaxAxes>;
    AxisVector q = start;
    PoseJacobian J;
    Eigen::Matrix<double, 6, 1> r;
    Eigen::SelfAdjointEigenSolver<Square> eig;
    for (int it = 0; it < iterations; ++it) {
        const ToolPose p = toolPose(actual, q, tip);
        r.head<3>() = target.tip - p.tip;
        r.tail<3>() = (target.axis - p.axis) * axisWeight;
        if (r.norm() < 1e-12) break;
        toolPoseJacobian(actual, q, tip, J);
        J.bottomRows<3>() *= axisWeight;
        // Truncated pseudo-inverse through the normal matrix JᵀJ = V·diag(σ²)·Vᵀ: directions whose singular value
        // is below 1e-4 of the largest (singular orientations, tool axis parallel to a rotary axis) get no step.
        const Square A = J.transpose() * J;
        eig.compute(A);
        const auto& lambda = eig.eigenvalues();
        const double cut = 1e-8 * lambda.maxCoeff();
        const AxisVector g = J.transpose() * r;
        AxisVector step = AxisVector::Zero(q.size());
        for (int k = 0; k < lambda.size(); ++k) {
            if (!(lambda[k] > cut)) continue;
            const auto v = eig.eigenvectors().col(k);
            step += v * (v.dot(g) / lambda[k]);
        }
        q += step;
    }
    return q;
}

}  // namespace cnccomp::controllers
