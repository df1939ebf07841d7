#pragma once
// A point or direction walked through a kinematic chain as three scalars, with Eigen's arithmetic term for term.
#include "cnccomp/geometry.hpp"

namespace cnccomp::xyz {

/// A point or direction as three scalars. As an Eigen Vec3 the compiler keeps (x, y) as one 16-byte value and z
/// apart: a rotation about X writes y alone, a rotation matrix's rows are written one by one, and the next operation
/// reads (x, y) whole, a load the processor cannot forward from the two stores (it waits for them to reach the
/// cache). The arithmetic is Eigen's, term for term and in its order of summation (below), so the bits are the same.
struct Xyz {
    double x, y, z;
};
inline Xyz toXyz(const Vec3& v) { return {v[0], v[1], v[2]}; }
inline Vec3 toVec3(const Xyz& p) { return Vec3(p.x, p.y, p.z); }

/// Rᵀ p as Eigen evaluates `R.transpose() * p` (a row of Rᵀ is a column of R, contiguous): the first two products
/// summed as a packet, then the third.
[[gnu::always_inline]] inline Xyz transposeTimes(const Mat3& R, const Xyz& p) {
    return {(R(0, 0) * p.x + R(1, 0) * p.y) + R(2, 0) * p.z, (R(0, 1) * p.x + R(1, 1) * p.y) + R(2, 1) * p.z,
            (R(0, 2) * p.x + R(1, 2) * p.y) + R(2, 2) * p.z};
}

/// R p as Eigen evaluates `R * p`: rows 0 and 1 as a packet, column after column ((a0 + a1) + a2); row 2 as one
/// coefficient's sum, halves first (a0 + (a1 + a2)).
[[gnu::always_inline]] inline Xyz times(const Mat3& R, const Xyz& p) {
    return {(R(0, 0) * p.x + R(0, 1) * p.y) + R(0, 2) * p.z, (R(1, 0) * p.x + R(1, 1) * p.y) + R(1, 2) * p.z,
            R(2, 0) * p.x + (R(2, 1) * p.y + R(2, 2) * p.z)};
}

/// (a, b) ← (c a + s b, c b − s a): a point turned back by θ in the plane (a, b) of a coordinate axis (c = cos θ,
/// s = sin θ), as KinematicsModel::rotateBack.
[[gnu::always_inline]] inline void turnBack(double c, double s, double& a, double& b) {
    const double va = a, vb = b;
    a = c * va + s * vb;
    b = c * vb - s * va;
}

}  // namespace cnccomp::xyz
