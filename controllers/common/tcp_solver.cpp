#include "controllers/common/tcp_solver.hpp"

#include <Eigen/SVD>

namespace cnccomp::controllers {

AxisVector compensatedCommands(const Kinematics& actual, const ToolPose& target, const Vec3& tip, const AxisVector& start,
                               int iterations, double axisWeight) {
    AxisVector q = start;
    PoseJacobian J;
    Eigen::Matrix<double, 6, 1> r;
    for (int it = 0; it < iterations; ++it) {
        const ToolPose p = toolPose(actual, q, tip);
        r.head<3>() = target.tip - p.tip;
        r.tail<3>() = (target.axis - p.axis) * axisWeight;
        if (r.norm() < 1e-12) break;
        toolPoseJacobian(actual, q, tip, J);
        J.bottomRows<3>() *= axisWeight;
        Eigen::JacobiSVD<PoseJacobian> svd(J, Eigen::ComputeThinU | Eigen::ComputeThinV);
        svd.setThreshold(1e-4);  // ignore directions ~1e4 times weaker than the strongest (singular orientations)
        const AxisVector step = svd.solve(r);
        q += step;
    }
    return q;
}

}  // namespace cnccomp::controllers
