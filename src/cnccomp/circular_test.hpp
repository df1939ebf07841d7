#pragma once
// ISO 230-4 evaluation of circular (ball-bar) runs: circular deviation G, radial deviation F (max, min), mean
// radius and circular hysteresis H, per pass and per run (ISO 230-4:2005, "Test code for machine tools — Part 4:
// Circular tests for numerically controlled machine tools", [IbarakiDBB5] ref. 4, which reports circularity and mean
// radial error per run in its Tables 3 and 4). Definitions as used here (clause numbers of ISO 230-4 [G]):
//  - radial deviation F: actual − nominal radius about the nominal centre (the centre ball), i.e. ΔL; F max, F min;
//  - circular deviation G: radial separation of the two concentric circles about the least-squares centre that
//    enclose the path (max − min distance from that centre);
//  - mean radius: radius of the least-squares circle (LB + mean radial error);
//  - circular hysteresis H: largest radial difference between the CCW and the CW path at the same angle. Radii
//    about any common centre give the same difference to first order (the centre terms cancel), so H is taken as
//    max |ΔL_ccw(θ) − ΔL_cw(θ)| with ΔL of one pass interpolated linearly at the other's angles, over the angles
//    both passes cover.
#include <limits>
#include <vector>

#include <Eigen/Core>

#include "cnccomp/ballbar.hpp"

namespace cnccomp {

/// One pass (or a whole trace) evaluated on its own.
struct CircularTestResult {
    int samples = 0;
    double circularity = 0;      ///< ISO 230-4 circular deviation G: max − min distance from the LSQ centre, mm
    double meanRadialError = 0;  ///< LSQ circle radius − LB, mm (= mean ΔL of a uniformly sampled full turn)
    double meanRadius = 0;       ///< LSQ circle radius, mm (LB + meanRadialError)
    double radialMax = 0, radialMin = 0;  ///< largest / smallest ΔL (radial deviation F about the nominal centre), mm
    double meanDeltaL = 0;       ///< plain average of ΔL, mm
    Eigen::Vector2d center = Eigen::Vector2d::Zero();  ///< LSQ centre of the polar plot (LB + ΔL at the angle), mm
    /// Least-squares Fourier terms of ΔL(θ) = a0 + a1 cos θ + b1 sin θ + a2 cos 2θ + b2 sin 2θ, mm.
    double a0 = 0, a1 = 0, b1 = 0, a2 = 0, b2 = 0;
};

/// Gander's geometric circle fit on the polar plot (works on arcs ≥ 90°) and a linear Fourier fit of ΔL.
/// Throws ModelError for fewer than five samples, mismatched sizes or non-finite values.
CircularTestResult evaluateCircularTest(const BallbarTrace& trace, double LB);

/// One recorded pass of a run: +1 = CCW (angle increasing), −1 = CW.
struct DirectedTrace {
    int direction = +1;
    BallbarTrace trace;
};

/// A run with one or two passes, as printed with the identification and shown in the report.
struct CircularRunResult {
    std::vector<CircularTestResult> passes;  ///< same order as the input
    std::vector<int> directions;
    double circularDeviation = 0;  ///< G: the largest of the passes' G (ISO 230-4 evaluates each direction), mm
    double radialMax = 0, radialMin = 0;  ///< F max / F min over every pass, mm
    double meanRadius = 0;         ///< mean of the passes' LSQ radii, mm
    double hysteresis = std::numeric_limits<double>::quiet_NaN();  ///< H, mm; NaN without a CCW and a CW pass
    int hysteresisSamples = 0;     ///< angles at which both passes were compared
};

/// Throws ModelError for no pass, a direction other than ±1, or a pass evaluateCircularTest() refuses.
CircularRunResult evaluateCircularRun(const std::vector<DirectedTrace>& passes, double LB);

/// H between two passes (see above): max |a(θ) − b(θ)| over the samples of either pass inside the other's angular
/// range, the other interpolated linearly. Returns NaN (and 0 in `compared`) when the ranges do not overlap.
double circularHysteresis(const BallbarTrace& a, const BallbarTrace& b, int* compared = nullptr);

}  // namespace cnccomp
