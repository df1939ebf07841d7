#pragma once
// Least-squares fits used to read geometric errors off R-test trajectories ([Moravek2019] section 2.2, after
// Gander, Golub & Strebel 1994, "Least-squares fitting of circles and ellipses"): planes (the "straight line in
// two planes perpendicular to the plane of interpolation", fitted jointly), circles in 3D, and ellipses —
// algebraic conic fit with ‖u‖ = 1, geometric fit in the parametric form x = z + Q(α)(a cos φ, b sin φ) by
// Gauss–Newton with the phases φ_i eliminated (Schur complement), and the parametric form with known phases.
#include <vector>

#include <Eigen/Core>

#include "cnccomp/geometry.hpp"

namespace cnccomp::identification {

struct PlaneFit {
    Vec3 centroid = Vec3::Zero();
    Vec3 normal = Vec3::UnitZ();  ///< unit; oriented along the hint given to fitPlane
    double rms = 0.0;             ///< RMS distance of the points from the plane
};
/// Total least squares: normal = direction of least spread of the centred points. Needs ≥ 3 non-collinear points.
PlaneFit fitPlane(const std::vector<Vec3>& points, const Vec3& normalHint);

struct Circle3Fit {
    Vec3 center = Vec3::Zero();
    Vec3 normal = Vec3::UnitZ();
    double radius = 0.0;
    double rms = 0.0;  ///< RMS of the in-plane radial residuals
};
/// Plane fit, then the geometric circle fit (Gander) of the points projected into that plane. Works on arcs.
Circle3Fit fitCircle3(const std::vector<Vec3>& points, const Vec3& normalHint);

/// Ellipse {z + Q(angle)·(a cos φ, b sin φ)}, a ≥ b ≥ 0, angle of the a-axis in (−π/2, π/2].
struct EllipseFit {
    Eigen::Vector2d center = Eigen::Vector2d::Zero();
    double a = 0.0, b = 0.0;
    double angle = 0.0;
    double rms = 0.0;  ///< RMS distance of the points from the fitted ellipse (geometric fits)
    int iterations = 0;
};

/// Algebraic fit: conic A x² + B xy + C y² + D x + E y + F = 0 minimising Σ (conic)² with ‖(A..F)‖ = 1, on
/// centred and scaled coordinates. Throws ModelError when the best conic is not an ellipse (e.g. collinear points).
EllipseFit fitEllipseAlgebraic(const std::vector<Eigen::Vector2d>& points);
/// Geometric fit (orthogonal distances) by Gauss–Newton in the parametric form, started from the algebraic fit.
EllipseFit fitEllipse(const std::vector<Eigen::Vector2d>& points);
/// Parametric form with known phases (e.g. the commanded rotary angle): x_i = z + U cos φ_i + V sin φ_i, a
/// linear least-squares problem; the ellipse's axes are the singular values of [U V]. Handles thin (degenerate)
/// ellipses, such as a circle seen edge-on.
EllipseFit fitEllipsePhases(const std::vector<Eigen::Vector2d>& points, const std::vector<double>& phases);

/// Diameter of the ellipse along the direction at `angle` (rad), through its centre (the D45 / D135 of [Moravek2019] eq. (2)).
double ellipseDiameter(const EllipseFit& e, double angle);

/// Distance from a point to an ellipse and the phase of the closest point (Newton on the phase).
double ellipseDistance(const EllipseFit& e, const Eigen::Vector2d& p, double* phase = nullptr);

}  // namespace cnccomp::identification
