#pragma once
// Least-squares circle fit (Gander, Golub & Strebel 1994): algebraic fit for a start, then Gauss–Newton on the
// geometric distances.
#include <vector>

#include <Eigen/Core>

namespace cnccomp {

struct CircleFit {
    Eigen::Vector2d center = Eigen::Vector2d::Zero();
    double radius = 0.0;
    double rms = 0.0;  ///< RMS of the geometric residuals
    int iterations = 0;
};

/// Algebraic (Kåsa) fit: minimises Σ (|p−c|² − r²)². Needs ≥ 3 non-collinear points; throws ModelError otherwise.
CircleFit fitCircleAlgebraic(const std::vector<Eigen::Vector2d>& points);
/// Geometric fit: minimises Σ (|p−c| − r)², started from the algebraic fit.
CircleFit fitCircle(const std::vector<Eigen::Vector2d>& points);

/// Residuals r_i = |p_i − c| − r and their Jacobian w.r.t. (cx, cy, r) (used by fitCircle; tested by finite differences).
void circleResiduals(const std::vector<Eigen::Vector2d>& points, const Eigen::Vector3d& params, Eigen::VectorXd& residuals,
                     Eigen::MatrixXd* jacobian);

}  // namespace cnccomp
