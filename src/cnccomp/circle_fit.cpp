#include "cnccomp/circle_fit.hpp"

#include <cmath>

#include <Eigen/Dense>

#include "cnccomp/error.hpp"

namespace cnccomp {

CircleFit fitCircleAlgebraic(const std::vector<Eigen::Vector2d>& pts) {
    const int n = static_cast<int>(pts.size());
    if (n < 3) throw ModelError("circle fit needs at least three points");
    // Centre the data for conditioning: x² + y² + D x + E y + F = 0.
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    for (const auto& p : pts) mean += p;
    mean /= n;
    Eigen::MatrixXd A(n, 3);
    Eigen::VectorXd b(n);
    for (int i = 0; i < n; ++i) {
        const Eigen::Vector2d d = pts[i] - mean;
        A(i, 0) = d.x();
        A(i, 1) = d.y();
        A(i, 2) = 1.0;
        b[i] = -d.squaredNorm();
    }
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeThinU | Eigen::ComputeThinV);
    const auto& s = svd.singularValues();
    if (!(s[2] > 1e-12 * s[0])) throw ModelError("circle fit: the points are collinear or coincide");
    const Eigen::Vector3d x = svd.solve(b);
    CircleFit f;
    f.center = mean + Eigen::Vector2d(-x[0] / 2, -x[1] / 2);
    const double r2 = x[0] * x[0] / 4 + x[1] * x[1] / 4 - x[2];
    if (!(r2 > 0)) throw ModelError("circle fit: no real circle through the points");
    f.radius = std::sqrt(r2);
    return f;
}

void circleResiduals(const std::vector<Eigen::Vector2d>& pts, const Eigen::Vector3d& p, Eigen::VectorXd& r,
                     Eigen::MatrixXd* J) {
    const int n = static_cast<int>(pts.size());
    r.resize(n);
    if (J) J->resize(n, 3);
    for (int i = 0; i < n; ++i) {
        const Eigen::Vector2d d = pts[i] - p.head<2>();
        const double dist = d.norm();
        r[i] = dist - p[2];
        if (J) {
            const Eigen::Vector2d g = dist > 0 ? Eigen::Vector2d(-d / dist) : Eigen::Vector2d::Zero();
            (*J)(i, 0) = g.x();
            (*J)(i, 1) = g.y();
            (*J)(i, 2) = -1.0;
        }
    }
}

CircleFit fitCircle(const std::vector<Eigen::Vector2d>& pts) {
    CircleFit f = fitCircleAlgebraic(pts);
    Eigen::Vector3d p(f.center.x(), f.center.y(), f.radius);
    Eigen::VectorXd r;
    Eigen::MatrixXd J;
    for (f.iterations = 0; f.iterations < 50; ++f.iterations) {
        circleResiduals(pts, p, r, &J);
        const Eigen::Vector3d step = J.colPivHouseholderQr().solve(-r);
        p += step;
        if (step.norm() <= 1e-15 * (1.0 + p.norm())) break;
    }
    circleResiduals(pts, p, r, nullptr);
    f.center = p.head<2>();
    f.radius = p[2];
    f.rms = std::sqrt(r.squaredNorm() / static_cast<double>(r.size()));
    return f;
}

}  // namespace cnccomp
