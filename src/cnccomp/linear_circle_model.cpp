#include "cnccomp/linear_circle_model.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>
#include <fmt/format.h>

#include "cnccomp/ballbar.hpp"
#include "cnccomp/circular_test.hpp"
#include "cnccomp/error.hpp"
#include "cnccomp/geometry.hpp"
#include "cnccomp/identification/identifiability.hpp"
#include "cnccomp/identification/levenberg_marquardt.hpp"

namespace cnccomp {
using namespace cnccomp::identification;

// Internals in a named namespace (not anonymous): the core may be compiled as unity units.
namespace linear_circle_detail {

// Canonical order of the diagnostic parameters (display units), then the nuisance of one pass.
enum Canon : int {
    kSquareness = 0, kScale, kStraightU, kStraightV,
    kBacklashUp, kBacklashUm, kBacklashVp, kBacklashVm,
    kSpikeUp, kSpikeUm, kSpikeVp, kSpikeVm,
    kPlayU, kPlayV, kCycUc, kCycUs, kCycVc, kCycVs, kServo,
    kDiag,                      // number of diagnostic parameters
    kCentU = kDiag, kCentV, kRadius,
    kCanon                      // diagnostics + nuisance of one pass
};

using CanonVector = Eigen::Matrix<double, kCanon, 1>;

CanonVector toCanon(const LinearCircleDiagnostics& d) {
    CanonVector c = CanonVector::Zero();
    c[kSquareness] = d.squareness;
    c[kScale] = d.scaleMismatch;
    c[kStraightU] = d.straightness[0];
    c[kStraightV] = d.straightness[1];
    for (int a = 0; a < 2; ++a)
        for (int e = 0; e < 2; ++e) {
            c[kBacklashUp + 2 * a + e] = d.backlash[a][e];
            c[kSpikeUp + 2 * a + e] = d.spike[a][e];
        }
    c[kPlayU] = d.lateralPlay[0];
    c[kPlayV] = d.lateralPlay[1];
    c[kCycUc] = d.cyclicCos[0];
    c[kCycUs] = d.cyclicSin[0];
    c[kCycVc] = d.cyclicCos[1];
    c[kCycVs] = d.cyclicSin[1];
    c[kServo] = d.servoMismatch;
    return c;
}

LinearCircleDiagnostics fromCanon(const CanonVector& c) {
    LinearCircleDiagnostics d;
    d.squareness = c[kSquareness];
    d.scaleMismatch = c[kScale];
    d.straightness = {c[kStraightU], c[kStraightV]};
    for (int a = 0; a < 2; ++a)
        for (int e = 0; e < 2; ++e) {
            d.backlash[a][e] = c[kBacklashUp + 2 * a + e];
            d.spike[a][e] = c[kSpikeUp + 2 * a + e];
        }
    d.lateralPlay = {c[kPlayU], c[kPlayV]};
    d.cyclicCos = {c[kCycUc], c[kCycVc]};
    d.cyclicSin = {c[kCycUs], c[kCycVs]};
    d.servoMismatch = c[kServo];
    return d;
}

/// A pass prepared for the model: unwrapped angles, travelled angles and the reversal history of every sample.
struct PassGeometry {
    int direction = 1;
    double omega = 0;  ///< rad/s
    std::vector<double> theta;  ///< rad, unwrapped
    struct Sample {
        std::array<std::array<int, 2>, 2> passed{};       ///< reversals passed, [axis][end]
        std::array<std::array<double, 2>, 2> spike{};     ///< Σ exp(−Δφ/φ₀) over them
        std::array<int, 2> motion{};                       ///< sgn of the commanded velocity of u, v
    };
    std::vector<Sample> samples;
};

std::vector<double> unwrapDegrees(const std::vector<double>& a) {
    std::vector<double> out(a.size());
    for (size_t i = 0; i < a.size(); ++i) {
        if (i == 0) {
            out[0] = a[0];
            continue;
        }
        double d = a[i] - a[i - 1];
        d -= 360.0 * std::round(d / 360.0);
        out[i] = out[i - 1] + d;
    }
    return out;
}

PassGeometry preparePass(const LinearCircle& circle, const LinearCirclePass& pass, double spikeDecayDeg) {
    if (pass.direction != 1 && pass.direction != -1)
        throw ModelError(fmt::format("linear circle: pass direction must be +1 (CCW) or −1 (CW), not {}",
                                     pass.direction));
    if (!(circle.radius > 0) || !std::isfinite(circle.radius))
        throw ModelError("linear circle: the radius must be a positive number (mm)");
    if (!(pass.feed > 0) || !std::isfinite(pass.feed))
        throw ModelError("linear circle: the feed must be a positive number (mm/min)");
    if (!std::isfinite(pass.startDeg) || !std::isfinite(pass.sweepDeg))
        throw ModelError("linear circle: the start and sweep of a pass must be finite numbers (degrees)");
    for (double a : pass.angleDeg)
        if (!std::isfinite(a)) throw ModelError("linear circle: sample angles must be finite numbers (degrees)");
    PassGeometry g;
    g.direction = pass.direction;
    g.omega = pass.feed / 60.0 / circle.radius;
    const int d = pass.direction;
    const std::vector<double> deg = unwrapDegrees(pass.angleDeg);
    if (deg.empty()) return g;
    // Start of the arc on the unwrapped scale (nearest turn to the first sample).
    const double start = pass.startDeg + 360.0 * std::round((deg[0] - pass.startDeg) / 360.0);
    // Reversals: u at θ ≡ 0 (+ end) and 180° (− end), v at 90° (+ end) and 270° (− end); travelled angles in (0, ∞).
    struct Event {
        double phi;
        int axis, end;
    };
    std::vector<Event> events;
    double lastPhi = 0;
    for (double a : deg) lastPhi = std::max(lastPhi, d * (a - start));
    for (int axis = 0; axis < 2; ++axis)
        for (int end = 0; end < 2; ++end) {
            const double at = 90.0 * axis + 180.0 * end;
            double phi = std::fmod(d * (at - start), 360.0);
            if (phi < 0) phi += 360.0;
            for (; phi <= lastPhi + 1e-9; phi += 360.0)
                if (phi > 1e-9) events.push_back({phi, axis, end});
        }
    // Direction of motion of each axis just after the start: u̇ ∝ −d sin θ, v̇ ∝ d cos θ.
    const double t0 = start * kDeg + d * 1e-7;
    const std::array<int, 2> motion0{-d * std::sin(t0) > 0 ? 1 : -1, d * std::cos(t0) > 0 ? 1 : -1};
    g.theta.resize(deg.size());
    g.samples.resize(deg.size());
    for (size_t i = 0; i < deg.size(); ++i) {
        g.theta[i] = deg[i] * kDeg;
        const double phi = d * (deg[i] - start);
        PassGeometry::Sample& s = g.samples[i];
        for (const Event& e : events) {
            if (!(e.phi < phi - 1e-9)) continue;
            ++s.passed[e.axis][e.end];
            if (spikeDecayDeg > 0) s.spike[e.axis][e.end] += std::exp(-(phi - e.phi) / spikeDecayDeg);
        }
        for (int a = 0; a < 2; ++a) s.motion[a] = (s.passed[a][0] + s.passed[a][1]) % 2 ? -motion0[a] : motion0[a];
    }
    return g;
}

/// ΔL (mm) of sample i and, when `grad` is given, ∂ΔL/∂(canonical parameter) (mm per display unit).
double evalSample(const LinearCircle& circle, const PassGeometry& g, size_t i, const LinearCircleSettings& set,
                  const CanonVector& p, CanonVector* grad) {
    const double R = circle.radius, th = g.theta[i];
    const int d = g.direction;
    const PassGeometry::Sample& s = g.samples[i];
    const double delta = d * g.omega * p[kServo] * 1e-3 / 2;  // rad
    const double xe = R * std::cos(th + delta), ye = R * std::sin(th - delta);
    const double eps = p[kScale] * 1e-6, alpha = p[kSquareness] * 1e-6;
    const double su = 1 + eps / 2, sv = 1 - eps / 2, sa = std::sin(alpha), ca = std::cos(alpha);
    std::array<double, 2> bk{}, sp{}, cyc{}, cycArg{}, cycDer{};
    for (int a = 0; a < 2; ++a) {
        bk[a] = p[kBacklashUp + 2 * a] * s.passed[a][0] - p[kBacklashUp + 2 * a + 1] * s.passed[a][1];
        sp[a] = p[kSpikeUp + 2 * a] * s.spike[a][0] - p[kSpikeUp + 2 * a + 1] * s.spike[a][1];
        const double pitch = set.cyclicPitch[a];
        if (pitch > 0) {
            const double k = kTwoPi / pitch;
            cycArg[a] = k * (a == 0 ? xe : ye);
            const double c = p[kCycUc + 2 * a], sn = p[kCycUs + 2 * a];
            cyc[a] = c * std::cos(cycArg[a]) + sn * std::sin(cycArg[a]);
            cycDer[a] = k * (-c * std::sin(cycArg[a]) + sn * std::cos(cycArg[a]));  // µm per mm of position
        }
    }
    const double ua = xe * su + ye * sv * sa + p[kStraightV] * kUm * (ye / R) * (ye / R) +
                      kUm * (bk[0] + sp[0] + p[kPlayV] * s.motion[1] / 2 + cyc[0]);
    const double va = ye * sv * ca + p[kStraightU] * kUm * (xe / R) * (xe / R) +
                      kUm * (bk[1] + sp[1] + p[kPlayU] * s.motion[0] / 2 + cyc[1]);
    const Eigen::Vector2d q(ua - p[kCentU] * kUm, va - p[kCentV] * kUm);
    const double len = q.norm();
    if (grad) {
        const Eigen::Vector2d n = q / len;
        CanonVector& G = *grad;
        G.setZero();
        G[kCentU] = -n.x() * kUm;
        G[kCentV] = -n.y() * kUm;
        G[kRadius] = kUm;
        G[kSquareness] = (n.x() * ye * sv * ca - n.y() * ye * sv * sa) * 1e-6;
        G[kScale] = (n.x() * (xe / 2 - ye * sa / 2) - n.y() * ye * ca / 2) * 1e-6;
        G[kStraightU] = n.y() * (xe / R) * (xe / R) * kUm;
        G[kStraightV] = n.x() * (ye / R) * (ye / R) * kUm;
        for (int a = 0; a < 2; ++a) {
            const double na = a == 0 ? n.x() : n.y();
            G[kBacklashUp + 2 * a] = na * s.passed[a][0] * kUm;
            G[kBacklashUp + 2 * a + 1] = -na * s.passed[a][1] * kUm;
            G[kSpikeUp + 2 * a] = na * s.spike[a][0] * kUm;
            G[kSpikeUp + 2 * a + 1] = -na * s.spike[a][1] * kUm;
            if (set.cyclicPitch[a] > 0) {
                G[kCycUc + 2 * a] = na * std::cos(cycArg[a]) * kUm;
                G[kCycUs + 2 * a] = na * std::sin(cycArg[a]) * kUm;
            }
        }
        G[kPlayU] = n.y() * s.motion[0] / 2 * kUm;
        G[kPlayV] = n.x() * s.motion[1] / 2 * kUm;
        const double dDelta = d * g.omega / 2 * 1e-3;  // rad per ms
        const double dxe = -R * std::sin(th + delta) * dDelta, dye = -R * std::cos(th - delta) * dDelta;
        const double dua = su * dxe + sv * sa * dye + p[kStraightV] * kUm * 2 * ye / (R * R) * dye +
                           kUm * cycDer[0] * dxe;
        const double dva = sv * ca * dye + p[kStraightU] * kUm * 2 * xe / (R * R) * dxe + kUm * cycDer[1] * dye;
        G[kServo] = n.x() * dua + n.y() * dva;
    }
    return len - R + p[kRadius] * kUm;
}

/// The unknowns of a fit: which canonical entry of which pass each column is.
struct Unknown {
    int canon = 0;
    int pass = -1;  ///< centring: its pass; else −1 (shared)
    std::string name, unit;
    bool nuisance = false;
};

std::string diagnosticName(int c, const std::array<char, 2>& ax, LinearPlane plane) {
    const char u = ax[0], v = ax[1];
    switch (c) {
        case kSquareness: return fmt::format("squareness {}", linearPlaneName(plane));
        case kScale: return fmt::format("scale mismatch {}-{}", u, v);
        case kStraightU: return fmt::format("straightness {} (along {})", u, v);
        case kStraightV: return fmt::format("straightness {} (along {})", v, u);
        case kBacklashUp: return fmt::format("backlash {}+", u);
        case kBacklashUm: return fmt::format("backlash {}-", u);
        case kBacklashVp: return fmt::format("backlash {}+", v);
        case kBacklashVm: return fmt::format("backlash {}-", v);
        case kSpikeUp: return fmt::format("reversal spike {}+", u);
        case kSpikeUm: return fmt::format("reversal spike {}-", u);
        case kSpikeVp: return fmt::format("reversal spike {}+", v);
        case kSpikeVm: return fmt::format("reversal spike {}-", v);
        case kPlayU: return fmt::format("lateral play {} (along {})", u, v);
        case kPlayV: return fmt::format("lateral play {} (along {})", v, u);
        case kCycUc: return fmt::format("cyclic error {} cos", u);
        case kCycUs: return fmt::format("cyclic error {} sin", u);
        case kCycVc: return fmt::format("cyclic error {} cos", v);
        case kCycVs: return fmt::format("cyclic error {} sin", v);
        case kServo: return "servo mismatch";
        default: return "?";
    }
}

const char* diagnosticUnit(int c) {
    return c == kSquareness || c == kScale ? "µm/m" : c == kServo ? "ms" : "µm";
}

const char* diagnosticModel(int c) {
    switch (c) {
        case kSquareness: return "ISO 230-1:2012 3.6.7; Kakino et al. 1993";
        case kScale: return "ISO 230-1:2012 (positioning of each axis); Kakino et al. 1993";
        case kStraightU:
        case kStraightV: return "ISO 230-1:2012 3.4.8, quadratic [G]";
        case kServo: return "Renishaw ballbar diagnostics (servo mismatch); Kakino et al. 1993";
        default:
            if (c >= kBacklashUp && c <= kBacklashVm) return "Renishaw ballbar diagnostics (backlash); Kakino 1993";
            if (c >= kSpikeUp && c <= kSpikeVm) return "Renishaw ballbar diagnostics (reversal spikes), shape [G]";
            if (c == kPlayU || c == kPlayV) return "Renishaw ballbar diagnostics (lateral play), sign [G]";
            return "Renishaw ballbar diagnostics (cyclic error)";
    }
}

}  // namespace linear_circle_detail

void checkLinearCirclePass(const LinearCirclePass& pass, int index) {
    using namespace linear_circle_detail;
    const std::string who = fmt::format("linear circle pass {} ({})", index + 1, pass.direction > 0 ? "CCW" : "CW");
    if (pass.direction != 1 && pass.direction != -1)
        throw ModelError(fmt::format("{}: direction must be +1 (CCW) or −1 (CW), not {}", who, pass.direction));
    if (!(pass.feed > 0) || !std::isfinite(pass.feed))
        throw ModelError(fmt::format("{}: the feed must be a positive number (mm/min)", who));
    if (!std::isfinite(pass.startDeg) || !(pass.sweepDeg > 0) || !(pass.sweepDeg <= 720))
        throw ModelError(fmt::format("{}: the arc must have a finite start and a sweep in (0, 720] degrees", who));
    if (pass.angleDeg.size() != pass.dL.size())
        throw ModelError(fmt::format("{}: {} angles but {} ΔL values; expected one ΔL per angle", who,
                                     pass.angleDeg.size(), pass.dL.size()));
    if (pass.angleDeg.size() < 8)
        throw ModelError(fmt::format("{}: {} samples; at least 8 are needed", who, pass.angleDeg.size()));
    for (size_t i = 0; i < pass.dL.size(); ++i)
        if (!std::isfinite(pass.angleDeg[i]) || !std::isfinite(pass.dL[i]))
            throw ModelError(fmt::format("{}: sample {} is not a finite number (angle {}, ΔL {})", who, i + 1,
                                         pass.angleDeg[i], pass.dL[i]));
    const std::vector<double> deg = unwrapDegrees(pass.angleDeg);
    const int d = pass.direction;
    std::vector<double> steps;
    for (size_t i = 1; i < deg.size(); ++i) {
        const double step = d * (deg[i] - deg[i - 1]);
        if (!(step > 0))
            throw ModelError(fmt::format("{}: the angle of sample {} ({}°) does not move {} from the previous one; "
                                         "expected angles monotone in the pass direction",
                                         who, i + 1, pass.angleDeg[i], d > 0 ? "up (CCW)" : "down (CW)"));
        steps.push_back(step);
    }
    std::vector<double> sorted = steps;
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(sorted.size() / 2), sorted.end());
    const double spacing = sorted[sorted.size() / 2];
    const double tol = std::max(1.0, 1.5 * spacing), gapMax = std::max(10.0, 3 * spacing);
    for (size_t i = 0; i < steps.size(); ++i)
        if (steps[i] > gapMax)
            throw ModelError(fmt::format("{}: a gap of {:.3g}° between samples {} and {}; expected no gap over {:.3g}°",
                                         who, steps[i], i + 1, i + 2, gapMax));
    const double start = pass.startDeg + 360.0 * std::round((deg[0] - pass.startDeg) / 360.0);
    const double first = d * (deg.front() - start), last = d * (deg.back() - start);
    if (std::abs(first) > tol || std::abs(last - pass.sweepDeg) > tol)
        throw ModelError(fmt::format("{}: the samples cover {:.4g}° to {:.4g}° of travel from the start {}°, but the pass "
                                     "states a {}° arc; expected the data to cover the arc within {:.3g}°",
                                     who, first, last, pass.startDeg, pass.sweepDeg, tol));
}

namespace {

/// The diagnostics with the set-up's centring and radius offset as the model's parameter vector (finite, else
/// ModelError).
linear_circle_detail::CanonVector canonParameters(const LinearCircleDiagnostics& d, const Eigen::Vector2d& centringUm,
                                                  double radiusOffsetUm) {
    using namespace linear_circle_detail;
    CanonVector p = toCanon(d);
    p[kCentU] = centringUm.x();
    p[kCentV] = centringUm.y();
    p[kRadius] = radiusOffsetUm;
    if (!p.allFinite()) throw ModelError("linear circle: the parameters must be finite numbers");
    return p;
}

}  // namespace

std::vector<double> predictLinearCircle(const LinearCircle& circle, const LinearCirclePass& pass,
                                        const LinearCircleDiagnostics& d, const Eigen::Vector2d& centringUm,
                                        double radiusOffsetUm, const LinearCircleSettings& settings) {
    using namespace linear_circle_detail;
    const PassGeometry g = preparePass(circle, pass, settings.spikeDecayDeg);
    const CanonVector p = canonParameters(d, centringUm, radiusOffsetUm);
    std::vector<double> out(g.theta.size());
    for (size_t i = 0; i < out.size(); ++i) out[i] = evalSample(circle, g, i, settings, p, nullptr);
    return out;
}

Eigen::MatrixXd linearCircleJacobian(const LinearCircle& circle, const LinearCirclePass& pass,
                                     const LinearCircleDiagnostics& d, const Eigen::Vector2d& centringUm,
                                     double radiusOffsetUm, const LinearCircleSettings& settings) {
    using namespace linear_circle_detail;
    const PassGeometry g = preparePass(circle, pass, settings.spikeDecayDeg);
    const CanonVector p = canonParameters(d, centringUm, radiusOffsetUm);
    Eigen::MatrixXd J(static_cast<Eigen::Index>(g.theta.size()), static_cast<Eigen::Index>(kCanon));
    CanonVector G;
    for (size_t i = 0; i < g.theta.size(); ++i) {
        (void)evalSample(circle, g, i, settings, p, &G);
        J.row(static_cast<Eigen::Index>(i)) = G.transpose();
    }
    return J;
}

LinearCircleFit identifyLinearCircle(const LinearCircle& circle, const std::vector<LinearCirclePass>& passes,
                                     const LinearCircleSettings& set) {
    using namespace linear_circle_detail;
    if (passes.empty()) throw ModelError("linear circle: no pass to identify from; expected at least one");
    if (!circle.centre.allFinite()) throw ModelError("linear circle: the centre must be finite numbers (mm)");
    std::vector<PassGeometry> geo;
    int m = 0;
    for (size_t k = 0; k < passes.size(); ++k) {
        checkLinearCirclePass(passes[k], static_cast<int>(k));
        geo.push_back(preparePass(circle, passes[k], set.spikeDecayDeg));
        m += static_cast<int>(passes[k].dL.size());
    }
    const std::array<char, 2> ax = linearPlaneAxes(circle.plane);

    // Unknowns: the diagnostics estimated, then ρ, then the centring of each pass.
    std::vector<Unknown> U;
    for (int c = 0; c < kDiag; ++c) {
        if (c >= kSpikeUp && c <= kSpikeVm && !(set.spikeDecayDeg > 0)) continue;
        if ((c == kCycUc || c == kCycUs) && !(set.cyclicPitch[0] > 0)) continue;
        if ((c == kCycVc || c == kCycVs) && !(set.cyclicPitch[1] > 0)) continue;
        U.push_back({c, -1, diagnosticName(c, ax, circle.plane), diagnosticUnit(c), false});
    }
    U.push_back({kRadius, -1, "radius offset", "µm", true});
    for (int k = 0; k < static_cast<int>(passes.size()); ++k) {
        U.push_back({kCentU, k, fmt::format("centring {} (pass {})", ax[0], k + 1), "µm", true});
        U.push_back({kCentV, k, fmt::format("centring {} (pass {})", ax[1], k + 1), "µm", true});
    }
    const int n = static_cast<int>(U.size());
    if (m <= n)
        throw ModelError(fmt::format("linear circle: {} samples for {} unknowns; expected more samples", m, n));

    Eigen::VectorXd measured(m);
    {
        int row = 0;
        for (const LinearCirclePass& p : passes)
            for (double v : p.dL) measured[row++] = v;
    }
    const auto canonOf = [&](const Eigen::VectorXd& x, int pass) {
        CanonVector c = CanonVector::Zero();
        for (int j = 0; j < n; ++j)
            if (U[j].pass < 0 || U[j].pass == pass) c[U[j].canon] = x[j];
        return c;
    };
    const auto evaluate = [&](const Eigen::VectorXd& x, Eigen::VectorXd& r, Eigen::MatrixXd* J) {
        r.resize(m);
        if (J) J->setZero(m, n);
        int row = 0;
        CanonVector G;
        for (size_t k = 0; k < passes.size(); ++k) {
            const CanonVector p = canonOf(x, static_cast<int>(k));
            for (size_t i = 0; i < geo[k].theta.size(); ++i, ++row) {
                r[row] = measured[row] - evalSample(circle, geo[k], i, set, p, J ? &G : nullptr);
                if (J)
                    for (int j = 0; j < n; ++j)
                        if (U[j].pass < 0 || U[j].pass == static_cast<int>(k)) (*J)(row, j) = -G[U[j].canon];
            }
        }
    };

    // First-order identifiability at the nominal machine, columns scaled to unit norm.
    Eigen::VectorXd x = Eigen::VectorXd::Zero(n), r;
    Eigen::MatrixXd J;
    evaluate(x, r, &J);
    Eigen::VectorXd scale(n);
    for (int j = 0; j < n; ++j) {
        const double c = J.col(j).norm();
        scale[j] = c > 0 ? 1.0 / c : 1.0;
    }
    const JacobianSvd nominal = decomposeJacobian(J * scale.asDiagonal(), set.rankTolerance);
    const int rank = nominal.rank;
    const Eigen::MatrixXd B = nominal.V.leftCols(rank), N = nominal.V.rightCols(n - rank);

    LinearCircleFit fit;
    fit.observations = m;
    fit.unknowns = n;
    fit.rank = rank;
    fit.dof = m - rank;
    fit.rmsBefore = std::sqrt(measured.squaredNorm() / m) / kUm;

    // Gauss–Newton in the observable subspace (the model is close to linear in its parameters; a step that raises
    // the cost is halved).
    double cost = r.squaredNorm();
    for (int it = 0; it < set.maxIterations; ++it) {
        fit.iterations = it + 1;
        const Eigen::MatrixXd Js = J * scale.asDiagonal() * B;
        const JacobianSvd s = decomposeJacobian(Js, set.rankTolerance, &r);
        Eigen::VectorXd z = Eigen::VectorXd::Zero(rank);
        for (int i = 0; i < s.rank; ++i) z += s.V.col(i) * (s.projected[i] / s.singular[i]);
        const Eigen::VectorXd dx = -(scale.asDiagonal() * (B * z));  // r = meas − pred, J = ∂r/∂x
        // Converged when the Gauss–Newton step is below 1e-9 of the point (scaled units, B orthonormal).
        if (z.norm() <= 1e-9 * (scale.cwiseInverse().asDiagonal() * x).norm() + 1e-12) break;
        double lambda = 1;
        bool accepted = false;
        Eigen::VectorXd xn, rn;
        for (int h = 0; h < 8; ++h, lambda /= 2) {
            xn = x + lambda * dx;
            evaluate(xn, rn, nullptr);
            if (rn.squaredNorm() <= cost) {
                accepted = true;
                break;
            }
        }
        if (!accepted) break;
        const double drop = cost - rn.squaredNorm();
        x = xn;
        cost = rn.squaredNorm();
        evaluate(x, r, &J);
        if ((scale.cwiseInverse().asDiagonal() * (lambda * dx)).norm() < 1e-10 || drop <= 1e-14 * cost) break;
    }

    // Covariance at the solution, restricted to the observable subspace.
    fit.sigma = fit.dof > 0 ? std::sqrt(cost / fit.dof) / kUm : kNaN;
    const double s2 = fit.dof > 0 ? cost / fit.dof : kNaN;
    Eigen::MatrixXd cov;
    {
        const Eigen::MatrixXd Js = J * scale.asDiagonal() * B;
        const JacobianSvd s = decomposeJacobian(Js, set.rankTolerance);
        Eigen::MatrixXd covZ = Eigen::MatrixXd::Zero(rank, rank);
        for (int i = 0; i < s.rank; ++i) covZ += s.V.col(i) * s.V.col(i).transpose() / (s.singular[i] * s.singular[i]);
        if (s.rank < rank) fit.warnings.push_back("the Jacobian at the solution has lower rank than at the nominal");
        cov = scale.asDiagonal() * (s2 * B * covZ * B.transpose()) * scale.asDiagonal();
    }
    const double t = studentTQuantile(0.975, fit.dof);

    // Unidentified parameters and their groups (projector on the null space, as identifiability.hpp does).
    const Eigen::MatrixXd P = N * N.transpose();
    constexpr double kCoupled = 1e-6;
    std::vector<char> unidentified(n, 0);
    for (int j = 0; j < n; ++j) unidentified[j] = P(j, j) > kCoupled;
    int groups = 0;
    const std::vector<int> group = coupledGroups(P, unidentified, kCoupled, groups);
    for (int gi = 0; gi < groups; ++gi) {
        std::vector<int> idx;
        std::vector<std::string> names;
        for (int j = 0; j < n; ++j)
            if (group[j] == gi) {
                idx.push_back(j);
                names.push_back(U[j].name);
            }
        fit.confounded.push_back(names);
        // Identifiable functionals of the group: the eigenvectors of I − P_g with eigenvalue ≈ 1 (scaled units).
        const int k = static_cast<int>(idx.size());
        Eigen::MatrixXd M = Eigen::MatrixXd::Identity(k, k);
        for (int a = 0; a < k; ++a)
            for (int b = 0; b < k; ++b) M(a, b) -= P(idx[a], idx[b]);
        Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(M);
        for (int e = 0; e < k; ++e) {
            if (es.eigenvalues()[e] < 0.5) continue;
            std::vector<std::string> cn;
            std::vector<double> cc;
            Eigen::VectorXd b = Eigen::VectorXd::Zero(n);
            double lead = 0;
            for (int a = 0; a < k; ++a) {
                const double coef = es.eigenvectors()(a, e) / scale[idx[a]];  // functional on display units
                if (std::abs(es.eigenvectors()(a, e)) < 1e-6) continue;
                if (lead == 0) lead = coef;
                cn.push_back(U[idx[a]].name);
                cc.push_back(coef / lead);
                b[idx[a]] = coef / lead;
            }
            if (cn.empty()) continue;
            LinearCircleCombination c;
            c.text = formatCombination(cn, cc);
            c.value = b.dot(x);
            c.stddev = std::sqrt(std::max(0.0, b.dot(cov * b)));
            fit.identifiable.push_back(c);
        }
    }

    // Parameters.
    CanonVector diag = CanonVector::Zero();
    fit.nuisance.centring.assign(passes.size(), Eigen::Vector2d::Zero());
    for (int j = 0; j < n; ++j) {
        LinearCircleParameter e;
        e.name = U[j].name;
        e.unit = U[j].unit;
        e.nuisance = U[j].nuisance;
        e.identified = !unidentified[j];
        if (e.identified) {
            e.value = x[j];
            e.stddev = std::sqrt(std::max(0.0, cov(j, j)));
            e.lower95 = e.value - t * e.stddev;
            e.upper95 = e.value + t * e.stddev;
            if (U[j].canon == kCentU) fit.nuisance.centring[U[j].pass].x() = x[j];
            else if (U[j].canon == kCentV) fit.nuisance.centring[U[j].pass].y() = x[j];
            else if (U[j].canon == kRadius) fit.nuisance.radiusOffset = x[j];
            else diag[U[j].canon] = x[j];
        } else {
            e.value = e.stddev = e.lower95 = e.upper95 = kNaN;
        }
        fit.parameters.push_back(e);
    }
    fit.values = fromCanon(diag);

    // Measured circularity and the diagnostics' shares.
    const auto circularityOf = [&](const std::vector<std::vector<double>>& traces) {
        double G = 0;
        for (size_t k = 0; k < passes.size(); ++k) {
            BallbarTrace bt{passes[k].angleDeg, traces[k]};
            G = std::max(G, evaluateCircularTest(bt, circle.radius).circularity);
        }
        return G / kUm;
    };
    {
        std::vector<std::vector<double>> meas;
        for (const LinearCirclePass& p : passes) meas.push_back(p.dL);
        fit.measuredCircularity = circularityOf(meas);
    }
    const auto columnOf = [&](int canon) {
        for (int j = 0; j < n; ++j)
            if (U[j].canon == canon) return j;
        return -1;
    };
    for (int c = 0; c < kDiag; ++c) {
        const int j = columnOf(c);
        if (j < 0 || c == kCycUs || c == kCycVs) continue;
        LinearCircleDiagnostic dg;
        const bool cyclic = c == kCycUc || c == kCycVc;
        dg.name = cyclic ? fmt::format("cyclic error {}", ax[c == kCycUc ? 0 : 1]) : U[j].name;
        dg.unit = U[j].unit;
        dg.model = diagnosticModel(c);
        CanonVector only = CanonVector::Zero();
        if (cyclic) {
            const int j2 = j + 1;  // the sin column follows the cos column
            dg.identified = !unidentified[j] && !unidentified[j2];
            if (dg.identified) {
                const double a = x[j], b = x[j2], amp = std::hypot(a, b);
                const Eigen::Vector2d grad = amp > 0 ? Eigen::Vector2d(a / amp, b / amp) : Eigen::Vector2d(1, 0);
                Eigen::Matrix2d C;
                C << cov(j, j), cov(j, j2), cov(j2, j), cov(j2, j2);
                const double sd = std::sqrt(std::max(0.0, grad.dot(C * grad)));
                dg.value = amp;
                dg.lower95 = std::max(0.0, amp - t * sd);
                dg.upper95 = amp + t * sd;
                only[c] = a;
                only[c + 1] = b;
            }
        } else {
            dg.identified = !unidentified[j];
            if (dg.identified) {
                dg.value = x[j];
                dg.lower95 = fit.parameters[j].lower95;
                dg.upper95 = fit.parameters[j].upper95;
                only[c] = x[j];
            }
        }
        if (!dg.identified) {
            dg.value = dg.lower95 = dg.upper95 = kNaN;
            dg.circularity = dg.share = kNaN;
        } else if (only.isZero()) {
            dg.circularity = dg.share = 0;
        } else {
            std::vector<std::vector<double>> traces;
            for (size_t k = 0; k < passes.size(); ++k) {
                std::vector<double> tr(geo[k].theta.size());
                for (size_t i = 0; i < tr.size(); ++i) tr[i] = evalSample(circle, geo[k], i, set, only, nullptr);
                traces.push_back(std::move(tr));
            }
            dg.circularity = circularityOf(traces);
            dg.share = fit.measuredCircularity > 0 ? 100.0 * dg.circularity / fit.measuredCircularity : kNaN;
        }
        fit.diagnostics.push_back(dg);
    }
    std::stable_sort(fit.diagnostics.begin(), fit.diagnostics.end(),
                     [](const LinearCircleDiagnostic& a, const LinearCircleDiagnostic& b) {
                         const double sa = std::isfinite(a.share) ? a.share : -1, sb = std::isfinite(b.share) ? b.share : -1;
                         return sa > sb;
                     });
    return fit;
}

}  // namespace cnccomp
