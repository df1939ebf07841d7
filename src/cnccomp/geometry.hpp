#pragma once
// Small geometric vocabulary: poses are Eigen isometries named aMb (pose of frame b in frame a).
#include <cmath>

#include <Eigen/Geometry>
#include <numbers>

namespace cnccomp {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Pose = Eigen::Isometry3d;
using Vec6 = Eigen::Matrix<double, 6, 1>;

/// Every entry finite, as Eigen's allFinite, whose x − x test runs as an out-of-line loop at a runtime size (the hot
/// paths of `correct` ask it per solve, of an AxisVector and of the normal matrix' inverse).
template <class Derived>
bool allFinite(const Eigen::DenseBase<Derived>& m) {
    for (Eigen::Index c = 0; c < m.cols(); ++c)
        for (Eigen::Index r = 0; r < m.rows(); ++r)
            if (!std::isfinite(m(r, c))) return false;
    return true;
}

inline constexpr double kPi = std::numbers::pi;
inline constexpr double kTwoPi = 2.0 * std::numbers::pi;
inline constexpr double kDeg = kPi / 180.0;       ///< radians per degree
inline constexpr double kArcsec = kDeg / 3600.0;  ///< radians per arc second
inline constexpr double kUm = 1e-3;               ///< millimetres per micrometre

/// Exact rotation by a rotation vector (axis * angle); no small-angle truncation.
inline Mat3 rotationVector(const Vec3& w) {
    const double a = w.norm();
    if (a < 1e-300) return Mat3::Identity();
    return Eigen::AngleAxisd(a, w / a).toRotationMatrix();
}

/// Error transform of the six components (dx, dy, dz, a, b, c): translation then exact rotation
/// about the axis (a, b, c) — the exact counterpart of the papers' small-angle HTMs ([MultiTasking] eq. (2), (3), (8)).
inline Pose errorTransform(const Vec6& e) {
    Pose p = Pose::Identity();
    p.linear() = rotationVector(e.tail<3>());
    p.translation() = e.head<3>();
    return p;
}

/// Cross-product matrix: skew(a) · b = a × b.
inline Mat3 skew(const Vec3& a) {
    Mat3 m;
    m << 0, -a.z(), a.y(), a.z(), 0, -a.x(), -a.y(), a.x(), 0;
    return m;
}

/// Rotation by `angle` (rad) about unit `axis`.
inline Mat3 axisRotation(const Vec3& axis, double angle) {
    return Eigen::AngleAxisd(angle, axis).toRotationMatrix();
}

}  // namespace cnccomp
