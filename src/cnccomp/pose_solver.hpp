#pragma once
// The one damped least-squares step of cnccomp's inverse solvers and its singular-pose policy, on Eigen's
// fixed-maximum-size matrices (no allocation per call). Users: the core's solveToolPose (inverse_kinematics.hpp: the
// controllers' apply models, verify, maps) and correct's chord Newton (postproc/correction.hpp), which keeps the
// factorisation from one solve to the next.
//
// The step minimises |J·s − r|² + (q + s − ref)ᵀ D (q + s − ref): the normal equations (JᵀJ + D) s = Jᵀr − D(q − ref),
// solved by Cholesky (Eigen::LLT). J is the pose Jacobian with its tool-axis rows weighted (mm per rad), r the weighted
// residual, ref the rotary positions the damping pulls towards.
//
// The singular-pose policy (SingularPosePolicy): damped least squares with variable damping [NakamuraHanafusa1986],
// [Chiaverini1994], applied only in the ill-conditioned directions of the tool axis over the rotary axes (numerical
// filtering of the small singular values [MaciejewskiKlein1988]):
//   D = λ² Σᵢ φ(σᵢ) vᵢ vᵢᵀ   (rotary rows and columns only),
// σᵢ, vᵢ the singular values and right singular vectors of the tool axis' derivatives by the rotary axes (rad/rad: the
// sine of the angle between the tool axis and a rotary axis, for one axis), φ(σ) = (1 − σ/σ0)² below the zone σ0 and
// 0 above it: the solution is exact away from singular poses, and near one a rotary axis corrects at most about
// axisWeight/(2λ) times the tool-axis error it removes instead of swinging, fading in smoothly. σ0 → ∞ (zone ≤ 0)
// gives φ ≡ 1, the constant pull D = λ² I of every rotary axis (Tikhonov regularisation). The shape (1 − σ/σ0)² —
// continuous with zero slope at σ0 — is cnccomp's choice [G] (the papers weight by the smallest singular value). It is
// the one policy of every inverse solver; no floor is needed outside the zone: there every rotary direction turns the
// tool axis by at least σ0, so JᵀJ is regular wherever the slides place the tip.
// Configurations: correct (postproc/correction.hpp: λ² = rotaryDamping² + continuity², σ0 = singularSine = 0.1),
// solveToolPose (IkOptions: λ = rotaryRegularization, σ0 = singularZone; by default 0.1 mm/rad and no zone), the
// LinuxCNC kinematics component (controllers/linuxcnc/kins_component.hpp: λ = 10 mm/rad, σ0 = 0.1), whose realtime C
// (ck_damping) computes the same D by Jacobi rotations and which the apply model solves with solveToolPose. A pull
// weighted by the smallest singular value alone (formerly the component's) and the pseudo-inverse truncated at 1e-4
// of the largest singular value (formerly controllers/common/tcp_solver) were removed.
#include <cstdint>

#include <Eigen/Cholesky>

#include "cnccomp/inverse_kinematics.hpp"

namespace cnccomp {

/// Square matrix of up to kMaxAxes × kMaxAxes, stored in place.
using SmallMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxAxes, kMaxAxes>;
/// kMaxAxes × 6 at most: a gain from the weighted residual to the axes.
using GainMatrix = Eigen::Matrix<double, Eigen::Dynamic, 6, 0, kMaxAxes, 6>;

/// The singular-pose policy (file comment): variable damping D = λ² Σ φ(σᵢ) vᵢ vᵢᵀ of the rotary axes.
struct SingularPosePolicy {
    double damping = 0.0;  ///< λ, mm (weighted residual) per rad of rotary correction; 0: no damping
    double zone = 0.0;     ///< σ0 (rad/rad): damping acts in directions whose singular value is below it, weighted
                           ///< (1 − σ/σ0)²; ≤ 0: everywhere with weight 1 (the constant pull λ² I)
};

/// The rotary axes among `free` (bit i: axis i) of machine m, as a bit mask.
uint32_t rotaryAxes(const MachineModel& m, uint32_t free = ~0u);

/// JᵀJ (n × n) of a pose Jacobian.
void normalMatrix(const PoseJacobian& J, SmallMatrix& JtJ);

/// Conditioning of the tool axis over some axes: the eigen-decomposition of G = Jaᵀ Ja · scale, Ja the tool-axis rows
/// (3–5) of a pose Jacobian over those axes: eigenvalues σᵢ² ascending, unit eigenvectors as columns of V (k × k).
struct AxisConditioning {
    int k = 0;                 ///< number of axes
    int axes[kMaxAxes] = {};   ///< their indices, ascending
    AxisVector lambda;         ///< σᵢ², ascending
    SmallMatrix V;             ///< eigenvectors (columns), set only when asked for
    /// Decomposes at J for the axes in `axes` (bit i: axis i); `vectors` false: eigenvalues only. Closed form for
    /// k ≤ 3 (Eigen's computeDirect), Jacobi/QR (SelfAdjointEigenSolver) above.
    void compute(const PoseJacobian& J, uint32_t axes, double scale = 1.0, bool vectors = true);
    /// Smallest singular value σ₁ (≥ 0); 1 when there is no axis.
    double smallestSingularValue() const;
};

/// D (n × n) of `policy` from a conditioning computed with eigenvectors: λ² Σ φ(σᵢ) vᵢ vᵢᵀ in the rows and columns of
/// c's axes, 0 elsewhere. False (D left unset) when no direction is damped.
bool singularDamping(const SingularPosePolicy& policy, const AxisConditioning& c, int n, SmallMatrix& D);

/// The factorised normal matrix of the damped step: A = JᵀJ + D on the free axes (identity rows and columns for the
/// fixed ones) plus ridge·(1 + Aᵢᵢ) on the diagonal; its inverse by Cholesky and the gain A⁻¹Jᵀ (zero rows for fixed
/// axes). Kept by a caller that reuses J over several steps (chord Newton). The ridge only keeps a singular A
/// factorisable: the damping enters the step's fixed point through the right-hand side, the ridge does not.
struct DampedNormalFactor {
    SmallMatrix inverse;  ///< A⁻¹
    GainMatrix gain;      ///< A⁻¹ Jᵀ, zero rows for fixed axes
    /// Factorises; JtJ = JᵀJ (n × n), D null for no damping. False (inverse and gain zero: no step) when A is not
    /// positive definite (a NaN in J; with ridge 0 also a singular pose without damping).
    bool factor(const PoseJacobian& J, const SmallMatrix& JtJ, const SmallMatrix* D, uint32_t free,
                double ridge = 1e-12);
    /// The step A⁻¹ (Jᵀr − D·offset) on the free axes (0 on the fixed ones), offset = q − ref; D null: A⁻¹Jᵀr.
    void step(const Eigen::Matrix<double, 6, 1>& r, const SmallMatrix* D, const AxisVector& offset, uint32_t free,
              AxisVector& s) const;
};

}  // namespace cnccomp
