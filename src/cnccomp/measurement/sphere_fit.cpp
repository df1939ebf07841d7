#include "cnccomp/measurement/sphere_fit.hpp"

#include <cmath>

#include <Eigen/Cholesky>
#include <fmt/format.h>

#include "cnccomp/error.hpp"

namespace cnccomp::measurement {

SphereFit fitSphereKnownRadius(const std::vector<Vec3>& points, double radius, const Vec3& start) {
    if (points.size() < 4) throw ModelError(fmt::format("a sphere fit needs four or more touches, got {}", points.size()));
    if (!(radius > 0) || !start.allFinite()) throw ModelError("a sphere fit needs a positive radius and a finite start");
    SphereFit f;
    f.centre = start;
    for (int it = 0; it < 50; ++it) {
        Mat3 N = Mat3::Zero();
        Vec3 g = Vec3::Zero();
        for (const Vec3& p : points) {
            const Vec3 v = p - f.centre;
            const double d = v.norm();
            if (!(d > 1e-12)) throw ModelError("a sphere fit: a touch lies at the centre");
            const Vec3 j = -v / d;  // ∂(|p − c| − r)/∂c
            N += j * j.transpose();
            g += j * (d - radius);
        }
        Eigen::LDLT<Mat3> ldlt(N);
        if (ldlt.info() != Eigen::Success || ldlt.rcond() < 1e-10)
            throw ModelError("a sphere fit: the touches do not fix the centre (they lie on one line)");
        const Vec3 step = ldlt.solve(-g);
        f.centre += step;
        f.iterations = it + 1;
        if (step.norm() < 1e-15 * (1.0 + radius)) break;
    }
    double ss = 0;
    for (size_t i = 0; i < points.size(); ++i) {
        const double r = (points[i] - f.centre).norm() - radius;
        ss += r * r;
        if (std::abs(r) > f.maxResidual) f.maxResidual = std::abs(r), f.worst = static_cast<int>(i);
    }
    f.rms = std::sqrt(ss / static_cast<double>(points.size()));
    return f;
}

}  // namespace cnccomp::measurement
