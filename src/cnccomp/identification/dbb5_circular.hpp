#pragma once
// ISO 230-4 evaluation of one circular (ball-bar) run, as reported per run in seed 003 Tables 3 and 4:
// circularity (circular deviation G) and mean radial error, plus the Fourier terms used for squareness.
#include <Eigen/Core>

#include "cnccomp/ballbar.hpp"

namespace cnccomp {

struct CircularTestResult {
    int samples = 0;
    double circularity = 0;      ///< ISO 230-4 circular deviation G: max − min distance from the LSQ centre, mm
    double meanRadialError = 0;  ///< LSQ circle radius − LB, mm (= mean ΔL of a uniformly sampled full turn)
    double radialMax = 0, radialMin = 0;  ///< largest / smallest ΔL (radial deviation F about the nominal centre), mm
    double meanDeltaL = 0;       ///< plain average of ΔL, mm
    Eigen::Vector2d center = Eigen::Vector2d::Zero();  ///< LSQ centre of the polar plot (LB + ΔL at the angle), mm
    /// Least-squares Fourier terms of ΔL(θ) = a0 + a1 cos θ + b1 sin θ + a2 cos 2θ + b2 sin 2θ, mm.
    double a0 = 0, a1 = 0, b1 = 0, a2 = 0, b2 = 0;
};

/// Gander's geometric circle fit on the polar plot (works on arcs ≥ 90°) and a linear Fourier fit of ΔL.
/// Throws ModelError for fewer than five samples, mismatched sizes or non-finite values.
CircularTestResult evaluateCircularTest(const BallbarTrace& trace, double LB);

}  // namespace cnccomp
