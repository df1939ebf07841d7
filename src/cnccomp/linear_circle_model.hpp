#pragma once
// Ball-bar circle in a plane of two linear axes (ISO 230-4:2005 circular test on XY, YZ or ZX, any machine, 3-axis
// included): the forward model of the bar reading ΔL(θ) from a set of diagnostic parameters, and their
// least-squares identification from one or more passes (CW and CCW), with 95 % intervals, identifiability and each
// diagnostic's share of the circularity.
//
// Plane and angle. The plane has in-plane axes (u, v): XY → (X, Y), YZ → (Y, Z), ZX → (Z, X) (the cyclic order of
// ISO 841; the same convention as RunPlane in ballbar.hpp). θ is measured from +u towards +v; the commanded tool
// position at sample angle θ is C + R(cos θ, sin θ). A pass moves CCW (direction +1, θ increasing) or CW (−1). Every
// axis error below is a function of the command relative to the circle centre, x = R cos θ, y = R sin θ (so a
// deviation that is linear or constant in absolute position only moves the centre, which the centring takes up).
//
// Exact geometry: each sample's actual tool point P_a = (u_a, v_a) is built from the commands and the parameters,
// and ΔL = |P_a − e_k| − R + ρ, with e_k the centring offset of pass k and ρ the radius offset. No first-order
// expansion is made; the first-order signatures quoted below are what the tests check the exact model against.
//
// Parameters and their models (values in µm, µm/m or ms):
//  - centring offset e = (e_u, e_v) per pass (nuisance, µm): position of the bar's pivot (centre ball) relative to the
//    circle centre, ISO 230-4:2005 (the set-up eccentricity every ball-bar evaluation removes; Kakino et al. 1993,
//    "Accuracy inspection of NC machine tools by double ball bar method", ch. 3: ΔL ≈ −e_u cos θ − e_v sin θ).
//    One per pass because the level of the direction-dependent errors (backlash, lateral play) at a pass's first
//    sample depends on how the pass was entered; a pass's centring takes it up.
//  - radius offset ρ (nuisance, µm, shared by the passes): bar length / common scale of both axes / thermal growth
//    (ISO 230-4 mean radial deviation; one radius cannot tell them apart).
//  - squareness α (µm/m) between u and v, ISO 230-1:2012 3.6.7 (squareness between two linear axes): the v axis
//    moves along (sin α, cos α), so u_a += y·sin α, v_a = y·cos α; α > 0: included angle below 90° [G sign as
//    Renishaw prints it]. First order ΔL ≈ (αR/2) sin 2θ (Kakino 1993).
//  - scale mismatch ε (µm/m): scale of u minus scale of v (ISO 230-1 linear positioning error of each axis, the
//    common part being ρ): u_a = x(1 + ε/2), v_a = y(1 − ε/2). First order ΔL ≈ (εR/2) cos 2θ.
//  - straightness S_u, S_v (µm): a quadratic (bowed) deviation of each axis' path perpendicular to its motion,
//    ISO 230-1:2012 3.4.8 (straightness deviation), its linear part being squareness and its constant the centring:
//    moving u deflects v by S_u·(x/R)², moving v deflects u by S_v·(y/R)² (S = the bow at ±R relative to the
//    centre). [G quadratic shape: the lowest order a circle can separate from squareness.]
//  - backlash b_{u+}, b_{u−}, b_{v+}, b_{v−} (µm): a step in the axis' position when its command reverses
//    (Renishaw, "QC20-W ballbar system: diagnostics", backlash: a step in the plot at the axis reversal; Kakino 1993
//    lost motion). b_{u+} is the step at the reversal at the + end of u (θ = 0), b_{u−} at the − end (θ = 180°);
//    b > 0 steps the trace outward (lost motion: the axis lags its command). Within a pass the steps accumulate:
//    u_a += Σ (+b_{u+} at each + end passed, −b_{u−} at each − end passed), so each end's step is seen separately
//    when it lies strictly inside the pass (a reversal at a pass's first or last sample is not seen by that pass:
//    start data arcs off the reversals, as Renishaw's feed-in arc does).
//  - reversal spikes a_{u+}, a_{u−}, a_{v+}, a_{v−} (µm): a transient in the axis' position after its reversal,
//    outward like the backlash step, decaying as exp(−φ/φ₀) with the angle φ travelled since the reversal;
//    φ₀ = LinearCircleSettings::spikeDecayDeg (Renishaw diagnostics: "reversal spikes"; [G] exponential shape).
//  - lateral play l_u, l_v (µm): the carriage of one axis shifts perpendicular to its motion when that axis
//    reverses (Renishaw diagnostics: "lateral play": a step at the reversal of the other axis' plot): v_a +=
//    (l_u/2)·sgn(u̇_cmd), u_a += (l_v/2)·sgn(v̇_cmd). [G sign.]
//  - cyclic error c_u, s_u, c_v, s_v (µm): a sinusoid in each axis' position with the pitch p of its screw or
//    scale (input, LinearCircleSettings::cyclicPitch), u_a += c_u cos(2πx/p_u) + s_u sin(2πx/p_u) (Renishaw
//    diagnostics: "cyclic error"; phase relative to the circle centre). Reported as amplitude √(c² + s²) too.
//    Only estimated for an axis whose pitch is given (> 0).
//  - servo mismatch Δt (ms): v lags u by Δt (Renishaw diagnostics: "servo mismatch", a lag between the axes'
//    position loops; Kakino 1993 gain mismatch): u follows the command at θ + d·ωΔt/2 and v at θ − d·ωΔt/2,
//    ω = feed/R. First order ΔL ≈ −(R·d·ωΔt/2) sin 2θ: the squareness signature with a sign that follows the
//    direction d, so one pass cannot separate Δt from α (the pair is reported confounded); CW + CCW can.
//
// Identification: Gauss–Newton on the exact model with the analytic Jacobian, in the observable subspace of the
// first-order (nominal) Jacobian (decomposeJacobian of levenberg_marquardt.hpp, columns scaled to unit norm,
// rank tolerance relative to the largest singular value). Parameters with a component in its null space are
// reported unidentified (value NaN) with their confounded group and the identifiable combinations; the others
// get σ̂² = Σr²/(m − rank), Cov = σ̂² B(BᵀJᵀJB)⁻¹Bᵀ and x̂ ± t(0.975, m − rank)·σ (studentTQuantile).
//
// Share of the circularity (definition): for each diagnostic, the trace of each pass predicted with that
// diagnostic alone at its estimated value (no centring, no radius offset, everything else zero), evaluated like
// the measurement (ISO 230-4 circular deviation G about the least-squares centre, circular_test.hpp), the largest
// over the passes; its share = that G / the measured G (largest over the passes), in %. Shares do not add up to
// 100 % (G is not additive); diagnostics are ranked by share.
#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace cnccomp {

enum class LinearPlane { XY, YZ, ZX };
/// "XY" / "YZ" / "ZX" (inline: the plan reader names planes without the model's fitting code).
inline const char* linearPlaneName(LinearPlane p) {
    switch (p) {
        case LinearPlane::XY: return "XY";
        case LinearPlane::YZ: return "YZ";
        case LinearPlane::ZX: return "ZX";
    }
    return "?";
}
/// Axis letters (u, v) of the plane: XY → X, Y; YZ → Y, Z; ZX → Z, X.
inline std::array<char, 2> linearPlaneAxes(LinearPlane p) {
    switch (p) {
        case LinearPlane::XY: return {'X', 'Y'};
        case LinearPlane::YZ: return {'Y', 'Z'};
        case LinearPlane::ZX: return {'Z', 'X'};
    }
    return {'?', '?'};
}

/// The nominal circle: plane, centre (u, v) and radius, mm.
struct LinearCircle {
    LinearPlane plane = LinearPlane::XY;
    Eigen::Vector2d centre = Eigen::Vector2d::Zero();
    double radius = 100;
};

/// One recorded pass: direction, feed and the data arc it claims, with the samples.
struct LinearCirclePass {
    int direction = +1;       ///< +1 CCW (θ increasing), −1 CW
    double feed = 1000;       ///< mm/min (servo mismatch only)
    double startDeg = 0;      ///< θ of the first sample of the data arc
    double sweepDeg = 360;    ///< data arc, degrees (> 0), travelled in `direction`
    std::vector<double> angleDeg;  ///< commanded θ of each sample (wrapped or not: unwrapped along the pass)
    std::vector<double> dL;        ///< bar reading ΔL = L − R, mm
};

/// The diagnostic parameters (not the nuisance), display units. Index 0 = u, 1 = v; [axis][0] = + end, [1] = − end.
struct LinearCircleDiagnostics {
    double squareness = 0;     ///< µm/m
    double scaleMismatch = 0;  ///< µm/m, scale of u − scale of v
    std::array<double, 2> straightness{};  ///< µm: S_u (path of u, along v), S_v (path of v, along u)
    std::array<std::array<double, 2>, 2> backlash{};  ///< µm
    std::array<std::array<double, 2>, 2> spike{};     ///< µm
    std::array<double, 2> lateralPlay{};   ///< µm: l_u (u's carriage, along v), l_v
    std::array<double, 2> cyclicCos{}, cyclicSin{};  ///< µm
    double servoMismatch = 0;  ///< ms, v lagging u
};

/// Nuisance of a pass: centring offset (µm, u and v) and the shared radius offset ρ (µm).
struct LinearCircleNuisance {
    std::vector<Eigen::Vector2d> centring;  ///< one per pass, µm
    double radiusOffset = 0;                ///< µm
};

struct LinearCircleSettings {
    std::array<double, 2> cyclicPitch{};  ///< mm; 0 = no cyclic error estimated for that axis
    double spikeDecayDeg = 4;             ///< φ₀ of the reversal spike [G]; ≤ 0 = no spikes estimated
    double rankTolerance = 1e-7;          ///< relative singular value below which a direction is unobservable
    int maxIterations = 20;
};

/// ΔL (mm) of every sample of `pass` (its angleDeg), exact geometry. `centringUm`, `radiusOffsetUm` in µm.
/// Throws ModelError for a non-finite input, R ≤ 0, a direction other than ±1 or feed ≤ 0.
std::vector<double> predictLinearCircle(const LinearCircle& circle, const LinearCirclePass& pass,
                                        const LinearCircleDiagnostics& d, const Eigen::Vector2d& centringUm,
                                        double radiusOffsetUm, const LinearCircleSettings& settings = {});

/// ∂ΔL/∂p of every sample (rows) for the 22 parameters (columns) in this order: squareness, scale mismatch,
/// straightness u, v, backlash u+, u−, v+, v−, spike u+, u−, v+, v−, lateral play u, v, cyclic cos u, sin u,
/// cos v, sin v, servo mismatch, centring u, v, radius offset; mm per display unit (µm, µm/m, ms). Analytic: the
/// derivative of the exact model the identification uses (its Jacobian).
Eigen::MatrixXd linearCircleJacobian(const LinearCircle& circle, const LinearCirclePass& pass,
                                     const LinearCircleDiagnostics& d, const Eigen::Vector2d& centringUm,
                                     double radiusOffsetUm, const LinearCircleSettings& settings = {});

/// One estimated parameter (display units).
struct LinearCircleParameter {
    std::string name;   ///< e.g. "backlash X+", "centring Y (pass 2)"
    std::string unit;   ///< "µm", "µm/m", "ms"
    bool nuisance = false;
    bool identified = true;
    double value = 0, stddev = 0, lower95 = 0, upper95 = 0;  ///< NaN when unidentified
};

/// A reported diagnostic, ranked by its share of the circularity.
struct LinearCircleDiagnostic {
    std::string name;   ///< "squareness XY", "backlash X+", "cyclic error X", "servo mismatch", …
    std::string unit;
    std::string model;  ///< the source of its model (short citation)
    bool identified = true;
    double value = 0, lower95 = 0, upper95 = 0;  ///< cyclic: amplitude (interval by the delta method, lower ≥ 0)
    double circularity = 0;  ///< µm: G of the trace predicted with this diagnostic alone (largest over passes)
    double share = 0;        ///< % of the measured circularity
};

/// A linear combination the data can see, of a confounded group.
struct LinearCircleCombination {
    std::string text;   ///< e.g. "squareness XY + 0.5236·servo mismatch"
    double value = 0, stddev = 0;  ///< in the units of the first parameter
};

struct LinearCircleFit {
    std::vector<LinearCircleParameter> parameters;  ///< every unknown, in a fixed order
    std::vector<LinearCircleDiagnostic> diagnostics;  ///< ranked by share (unidentified last)
    LinearCircleDiagnostics values;    ///< identified values (unidentified ones 0)
    LinearCircleNuisance nuisance;
    std::vector<std::vector<std::string>> confounded;  ///< groups of unidentified parameters
    std::vector<LinearCircleCombination> identifiable; ///< identifiable combinations of those groups
    double sigma = 0;          ///< µm, σ̂ of the residual
    double rmsBefore = 0;      ///< µm, rms of the measured ΔL (about nothing)
    int observations = 0, unknowns = 0, rank = 0, dof = 0, iterations = 0;
    double measuredCircularity = 0;  ///< µm, ISO 230-4 G, largest over the passes
    std::vector<std::string> warnings;
};

/// Identifies the parameters from the passes of one circle. Throws ModelError for no pass, a pass that does not
/// cover its stated arc, non-monotone or non-finite samples, fewer samples than unknowns.
LinearCircleFit identifyLinearCircle(const LinearCircle& circle, const std::vector<LinearCirclePass>& passes,
                                     const LinearCircleSettings& settings = {});

/// Checks a pass against its stated arc: direction ±1, feed > 0, sweep in (0, 720]°, one ΔL per angle, ≥ 8 samples,
/// finite values, angles monotone in the pass direction (wrapped angles are unwrapped), first and last sample within
/// max(1°, 1.5 sample spacings) of the arc's ends, no gap over max(10°, 3 spacings). Throws ModelError naming the
/// pass (1-based) and what was expected. `index`: 0-based.
void checkLinearCirclePass(const LinearCirclePass& pass, int index);

}  // namespace cnccomp
