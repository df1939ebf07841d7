#pragma once
// A proven upper bound of a corrected straight TCP move's deviation at its midpoint, from what the correction already
// knows about the move's ends — no kinematics evaluated. Where the bound is below both the tolerance and the largest
// deviation already measured, the exact check (one inverse and one forward evaluation) cannot change anything the
// correction writes or reports, and is left out (Corrector::split, PathContext::midpointBound).
//
// The class of machines and moves: TCP angles mode; location errors only (no component errors); the workpiece chain
// holds only rotary axes and the tool chain the three linear slides (a table-table machine: LinuxCNC's xyzac-trt,
// xyzbc-trt); the TCP inverse exact (TcpModel::fixedSlides). Elsewhere usable() is false and every midpoint is checked.
//
// The proof (d = the deviation vector along the move, t ∈ [0, 1], both ends' program points interpolated linearly):
//   |d(½)| ≤ |d(0) + d(1)| / 2 + max|d''| / 8                                   (Taylor, integral remainder)
// - The chain from the base to the workpiece as a product of exponentials, W(θ) = Πᵢ exp(ξᵢθᵢ) · W(0) (joint lines
//   at θ = 0; Murray, Li, Sastry, "A Mathematical Introduction to Robotic Manipulation", 1994, §3.2), with rotation
//   R(θ) and translation t(θ) = Σᵢ (rotations before constant i) cᵢ, written as constants between rotations about
//   fixed unit axes; the erroneous chain is the same with other constants (an axis tilted by φ: a constant turn Q,
//   ‖Q − I‖ = |ω̃ − ω|, on either side of the rotation).
//   εR = Σ ‖R̃ᵢ − Rᵢ‖, εt = Σ |c̃ᵢ − cᵢ|, CW = Σ |cᵢ| over the constants (rotation, translation).
// - With R(θ) a product of rotations, each angle moving at rate Δθₖ: |R⁽ᵐ⁾| ≤ ωᵐ, ω = Σₖ |Δθₖ|, and
//   |(R̃ − R)⁽ᵐ⁾| ≤ εR ωᵐ (telescoping, Leibniz). The tool slides: base tool point T0 + S x + L u (erroneous T̃0, S̃,
//   ũ); the nominal inverse x = S⁻¹(W(θ) p − T0 − Lc u); K = S̃ S⁻¹ − I.
// - Then d(t) = (R̂ − I) p + t̂ + (p − pₙ) + R̃ᵀK(R p + t) + R̃ᵀ w + (L − Lc)[R̃ᵀ(θc) − Rᵀ(θn)] u with R̂ = R̃ᵀR,
//   t̂ = R̃ᵀ(t − t̃), w = (T̃0 − T0) − K (T0 + Lc u) + L (ũ − u), p the workpiece point of the corrected interpolation
//   (θc its angles), pₙ and θn the nominal path's. Term by term (τ = εR CW + εt, P = max |p|, v = |Δp|,
//   ω, ωn the rotary steps of the corrected and the nominal move, ω̄ = max(ω, ωn), δ the rotary corrections θc − θn
//   at the ends, Δδ their change):
//   |d''| ≤ εR (4ω²P + 4ωv) + 4ω²τ + |K| (4ω²(P + CW) + 4ωv) + ω²|w| + |L − Lc| (εR ω² + ω̄² max|δ|₁ + 2ω̄ |Δδ|₁).
// - d(1): the end solve's tip residual before its last step, plus that step's effect (≤ solveTolerance per slide,
//   solveTolerance / 100 per rotary axis, times the slides' and the rotary axes' levers).
// - d(0): the previous move's d(1), plus the change from its unrounded end to the written start (the output's
//   digits): ≤ (1 + |K|) |Δp| + |Δθ|₁ (2εR P + 2τ + 2|K| (P + CW) + |w + (L − Lc) u|).
// - Round-off: the bound is raised by 1e-6 of itself and 1e-9 mm (the evaluations agree with exact arithmetic to
//   1e-12 mm on these magnitudes).
// tests/postproc/test_midpoint_bound.cpp compares the bound with the exact check on random moves and deviation sets.
#include "cnccomp/kinematics_engine.hpp"
#include "postproc/tcp_model.hpp"

namespace cnccomp::postproc {

class MidpointBound {
public:
    MidpointBound() = default;
    /// The bound of one machine: `nominal` and `actual` its nominal and erroneous models, `tcp` the controller's TCP
    /// kinematics on `nominal`, `locationOnly` the deviation set has no component error.
    MidpointBound(const KinematicsModel& nominal, const KinematicsModel& actual, const TcpModel& tcp,
                  bool locationOnly);

    /// The machine and its deviation set are in the class (see the file comment).
    bool usable() const { return usable_; }

    /// Bound of |d(1)|, the deviation at a solved end point: `tipError` the solve's residual (SolveResult), `c` its
    /// machine coordinates, converged with step tolerance `solveTolerance` (mm).
    double endBound(double tipError, const AxisVector& c, double toolLength, double solveTolerance) const;

    /// Bound of the deviation at the midpoint of the straight move from the written start `outStart` to the corrected
    /// end `end` (program space), nominally from `nomStart` to `nomEnd`; the previous move ended (unrounded) at
    /// `prevEnd` with endBound `prevEndBound`, this one with `endBound`; tool length L, controller's length Lc.
    double midpoint(double toolLength, double controlLength, const AxisVector& outStart, const AxisVector& end,
                    const AxisVector& nomStart, const AxisVector& nomEnd, const AxisVector& prevEnd,
                    double prevEndBound, double endBound) const;

    /// The curvature term max|d''| / 8 alone (for the tests: the bound without it must fail somewhere).
    double curvatureTerm(double toolLength, double controlLength, const AxisVector& outStart, const AxisVector& end,
                         const AxisVector& nomStart, const AxisVector& nomEnd) const;

private:
    /// d(0)'s bound less the previous end's, and the curvature term (see the file comment).
    void parts(double toolLength, double controlLength, const AxisVector& outStart, const AxisVector& end,
               const AxisVector& nomStart, const AxisVector& nomEnd, const AxisVector& prevEnd, double& start,
               double& curvature) const;

    bool usable_ = false;
    const TcpModel* tcp_ = nullptr;
    int lin_[3] = {-1, -1, -1};
    int rotary_[kMaxAxes] = {};
    int rotaryCount_ = 0;
    Vec3 zeroLin_ = Vec3::Zero();  ///< model commands of machine zero, slides
    double epsR_ = 0, epsT_ = 0, cw_ = 0, cwActual_ = 0, tau_ = 0, k_ = 0;
    Vec3 worldOrigin_ = Vec3::Zero();  ///< the workpiece origin in TCP world coordinates (|p| = |x − it|)
    Vec3 t0_ = Vec3::Zero(), t0Actual_ = Vec3::Zero(), u_ = Vec3::UnitZ(), uActual_ = Vec3::UnitZ();
    Vec3 w0_ = Vec3::Zero(), wL_ = Vec3::Zero(), wLc_ = Vec3::Zero();  ///< w = w0 + L wL − Lc wLc
    double slidesActual_ = 0;  ///< ‖S̃‖ (Frobenius)
};

}  // namespace cnccomp::postproc
