#pragma once
// Least-squares sphere of known radius through touch points (the stylus ball centres at the touches).
//
// The radius is known: the sphere's radius plus the stylus ball's radius minus the probe's stated trigger offset
// (SphereRun::fitRadius). The probe's actual trigger offset (pre-travel: how far the stylus goes past the geometric
// contact before the probe switches) is a nuisance. cnccomp fits it as ONE unknown shared by every pose of a sphere
// run, in the identification (identification/sphere_probe.hpp), not per pose: it is a property of the probe and its
// feed, the same at every pose, so one unknown costs one degree of freedom in all instead of one per pose of five
// touches, and each pose keeps its centre along the tool axis as precise as the pole touch makes it (with a free
// radius per pose that component comes from the difference of the pole and the ring, whose noise is amplified by
// 1/(1 − sin latitude)). Not modelled: a trigger offset that depends on the touch direction (lobing).
#include <vector>

#include "cnccomp/geometry.hpp"

namespace cnccomp::measurement {

struct SphereFit {
    Vec3 centre = Vec3::Zero();
    double rms = 0;            ///< rms of |p − centre| − radius, mm
    double maxResidual = 0;    ///< largest |·|, mm
    int worst = -1;            ///< point with the largest residual
    int iterations = 0;
};

/// Minimises Σ (|p_i − c| − radius)² over c by Gauss–Newton from `start` (the nominal centre). Throws ModelError for
/// fewer than four points, a point at the centre or a pattern that does not fix the centre (all points on one line).
SphereFit fitSphereKnownRadius(const std::vector<Vec3>& points, double radius, const Vec3& start);

}  // namespace cnccomp::measurement
