#include "postproc/correction.hpp"

#include <algorithm>
#include <array>
#include <cmath>


namespace cnccomp::postproc {

namespace {

/// 2√k for k rotary axes, the same values as computed in place (std::sqrt rounds correctly): read from a table, the
/// square root's latency stood on the path of dampingFor's comparison.
const std::array<double, kMaxAxes + 1> kTwoRootOf = [] {
    std::array<double, kMaxAxes + 1> a{};
    for (int k = 0; k <= kMaxAxes; ++k) a[k] = 2.0 * std::sqrt(double(k));
    return a;
}();

/// out = a + t (b − a) element by element (as the Eigen expression; a loop, which Eigen's runtime-size assignment is not
/// inlined as).
inline void lerpAxes(const AxisVector& a, const AxisVector& b, double t, AxisVector& out) {
    const int n = static_cast<int>(a.size());
    out.resize(n);
    for (int i = 0; i < n; ++i) out[i] = a[i] + t * (b[i] - a[i]);
}

void lerpPoint(const ProgramPoint& a, const ProgramPoint& b, double t, bool vector, ProgramPoint& out) {
    lerpAxes(a.p, b.p, t, out.p);
    if (vector) out.v = slerpVector(a.v, b.v, t);
}
/// start += slope · step for n axes; N > 0: n = N known at compile time (the loops unrolled, the same sums).
template <int N>
void addSlopeStep(const SmallMatrix& slope, const double* step, AxisVector& start, int n = N) {
    const int m = N > 0 ? N : n;
    for (int i = 0; i < m; ++i) {
        double v = 0;
        for (int j = 0; j < m; ++j) v += slope(i, j) * step[j];
        start[i] += v;
    }
}
}  // namespace

Vec3 slerpVector(const Vec3& a, const Vec3& b, double t) {
    const double d = std::clamp(a.dot(b), -1.0, 1.0);
    const double angle = std::acos(d);
    if (angle < 1e-12) return (a + t * (b - a)).normalized();
    const double s = std::sin(angle);
    return (std::sin((1 - t) * angle) / s) * a + (std::sin(t * angle) / s) * b;
}

MovePath MovePath::line(const AxisVector& start, const AxisVector& end) {
    MovePath p;
    p.start = start;
    p.end = end;
    return p;
}

MovePath MovePath::arc(const AxisVector& start, const AxisVector& end, const ArcGeometry& g) {
    MovePath p;
    p.circular = true;
    p.start = start;
    p.end = end;
    p.axis0 = g.axis0;
    p.axis1 = g.axis1;
    p.c0 = g.c0;
    p.c1 = g.c1;
    p.r0 = std::hypot(start[g.axis0] - g.c0, start[g.axis1] - g.c1);
    p.r1 = std::hypot(end[g.axis0] - g.c0, end[g.axis1] - g.c1);
    p.theta0 = std::atan2(start[g.axis1] - g.c1, start[g.axis0] - g.c0);
    p.sweep = g.sweep;
    return p;
}

void MovePath::at(double t, ProgramPoint& q) const {
    lerpAxes(start, end, t, q.p);
    if (vector) q.v = slerpVector(v0, v1, t);
    if (!circular) return;
    const double th = theta0 + t * sweep, r = r0 + t * (r1 - r0);
    q.p[axis0] = c0 + r * std::cos(th);
    q.p[axis1] = c1 + r * std::sin(th);
}

Corrector::Corrector(const MachineModel& machine, const DeviationSet& deviations, const CorrectorOptions& options)
    : machine_(machine),
      nominal_(machine, nullptr),
      actual_(machine, &deviations),
      nominalData_(nominal_),
      actualData_(actual_),
      tcp_(nominal_, nominalData_),
      options_(options) {
    identity_ = deviations.values.size() == 0 || deviations.values.cwiseAbs().maxCoeff() == 0.0;
    affine_ = true;
    for (const DeviationDef& d : machine.deviations)
        if (d.kind == DeviationKind::Component)
            for (int k = 0; k < d.size(); ++k)
                if (deviations.values[d.offset + k] != 0.0) affine_ = false;
    for (int i = 0; i < machine.axisCount(); ++i)
        if (machine.axisLink(i).kind == AxisKind::Rotary) rotary_ |= 1u << i;
    zero_ = machine.fromController(AxisVector::Zero(machine.axisCount()));
    zeroIsZero_ = (zero_.array() == 0.0).all();
    if (!identity_ && options_.boundChecks) bound_ = MidpointBound(nominal_, actual_, tcp_, affine_);
}

Vec3 Corrector::actualTip(const AxisVector& c, double toolLength) {
    AxisVector scratch;
    // Usually at the rotary angles the nominal machine was just evaluated at (the commands of a checked point).
    actual_.takeAngles(actualData_, nominal_, nominalData_);
    return actual_.toolTipOnce(actualData_, model(c, scratch), toolLength);
}
Vec3 Corrector::nominalTip(const AxisVector& c, double toolLength) {
    AxisVector scratch;
    return nominal_.toolTip(nominalData_, model(c, scratch), toolLength);
}

const AxisVector& Corrector::model(const AxisVector& c, AxisVector& scratch) const {
    if (zeroIsZero_) return c;
    scratch = c + zero_;
    return scratch;
}

Vec3 Corrector::tipError(const AxisVector& cNom, const AxisVector& c, double toolLength) {
    return nominalTip(cNom, toolLength) - actualTip(c, toolLength);
}

bool Corrector::toJoints(const MoveSpace& s, const ProgramPoint& p, const AxisVector& guess, AxisVector& c,
                         NominalPose* pose) {
    if (pose) pose->known = false;
    switch (s.mode) {
        case ProgramMode::Joints:
            c = p.p;
            return true;
        case ProgramMode::TcpAngles:
            if (pose) {
                pose->known = tcp_.toJoints(nominalData_, p.p, s.controlLength, c, &pose->tip, &pose->axis);
                pose->length = s.controlLength;
            } else {
                tcp_.toJoints(nominalData_, p.p, s.controlLength, c);
            }
            return allFinite(c);
        case ProgramMode::TcpVector: {
            // The tool axis depends on the rotary axes only: Gauss–Newton on them (fresh Jacobian, limited steps),
            // then the linear axes exactly for the point, as in angles mode.
            const Vec3 target = tcp_.axisFromWorld(p.v.normalized());
            const int n = static_cast<int>(p.p.size());
            auto angles = [&](AxisVector& q) {
                PoseJacobian J;
                Vec3 tip, axis;
                for (int it = 0; it < 60; ++it) {
                    nominal_.jacobian(nominalData_, q + zero_, s.controlLength, J, tip, axis);
                    const Vec3 r = target - axis;
                    if (r.norm() < 1e-13) return true;
                    Eigen::Matrix<double, 3, Eigen::Dynamic, 0, 3, kMaxAxes> Jr(3, 0);
                    int cols[kMaxAxes], m = 0;
                    for (int i = 0; i < n; ++i)
                        if (rotary_ & (1u << i)) cols[m++] = i;
                    Jr.resize(3, m);
                    for (int k = 0; k < m; ++k) Jr.col(k) = J.block<3, 1>(3, cols[k]);
                    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxAxes, kMaxAxes> A = Jr.transpose() * Jr;
                    A.diagonal().array() += 1e-10;
                    Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxAxes, 1> d = A.ldlt().solve(Jr.transpose() * r);
                    const double big = d.cwiseAbs().maxCoeff();
                    if (big > 0.3) d *= 0.3 / big;
                    for (int k = 0; k < m; ++k) q[cols[k]] += d[k];
                    if (big < 1e-14) break;
                }
                nominal_.toolPose(nominalData_, q + zero_, s.controlLength, tip, axis);
                return (target - axis).norm() < 1e-9;
            };
            // The controller takes the solution nearest its position (the branch of the previous block) [G]: Newton
            // from there finds it when the orientation changes little; from far or from a singular start (tool axis
            // along a rotary axis) it may reach another branch: then other starts, the nearest wins.
            AxisVector best, q = guess;
            double bestDistance = HUGE_VAL;
            auto consider = [&](const AxisVector& start) {
                q = start;
                if (!angles(q)) return;
                const double dist = (q - guess).cwiseAbs().maxCoeff();
                if (dist < bestDistance) bestDistance = dist, best = q;
            };
            consider(guess);
            if (!(bestDistance < kPi / 6)) {
                static constexpr double kFirst[4] = {-60, -20, 20, 60}, kOther[4] = {-135, -45, 45, 135};  // deg
                for (int k = 0; k < 16; ++k) {
                    AxisVector start = guess;
                    int bits = k, which = 0;
                    for (int i = 0; i < n; ++i)
                        if (rotary_ & (1u << i)) {
                            start[i] = guess[i] + (which++ == 0 ? kFirst[bits & 3] : kOther[bits & 3]) * kDeg;
                            bits >>= 2;
                        }
                    consider(start);
                }
            }
            if (bestDistance == HUGE_VAL) return false;
            AxisVector withAngles = p.p;
            for (int i = 0; i < n; ++i)
                if (rotary_ & (1u << i)) withAngles[i] = best[i];
            tcp_.toJoints(nominalData_, withAngles, s.controlLength, c);
            return allFinite(c);
        }
    }
    return false;
}

void Corrector::toProgram(const MoveSpace& s, const AxisVector& c, ProgramPoint& p) {
    switch (s.mode) {
        case ProgramMode::Joints:
            p.p = c;
            return;
        case ProgramMode::TcpAngles:
            tcp_.toProgram(nominalData_, c, s.controlLength, p.p);
            return;
        case ProgramMode::TcpVector: {
            Vec3 point, axis;
            tcp_.forward(nominalData_, c, s.controlLength, point, axis);
            p.p = c;
            for (int k = 0; k < 3; ++k) p.p[tcp_.linearAxis(k)] = point[k];
            p.v = axis;
            return;
        }
    }
}

bool Corrector::cacheUsable(const JacobianCache& cache, const AxisVector& q, double toolLength) const {
    if (!cache.valid || cache.toolLength != toolLength || cache.q.size() != q.size()) return false;
    for (int i = 0; i < q.size(); ++i) {
        const double d = std::fabs(q[i] - cache.q[i]);
        if ((rotary_ & (1u << i)) ? d > 4.0 * kDeg : d > 50.0) return false;
    }
    return true;
}

void Corrector::refreshJacobian(const KinematicsModel& k, KinematicsData& kd, JacobianCache& cache, const AxisVector& q,
                                double toolLength) const {
    Vec3 tip, axis;
    k.jacobian(kd, q, toolLength, cache.J, tip, axis);
    cache.J.bottomRows<3>() *= options_.axisWeight;
    normalMatrix(cache.J, cache.JtJ);
    cache.q = q;
    cache.toolLength = toolLength;
    cache.valid = true;
    cache.factored = false;
    cache.slopeValid = false;
    cache.sigmaFree = ~0u;
}

void Corrector::factor(JacobianCache& cache, const Damping& damping, AxisMask free) const {
    cache.normal.factor(cache.J, cache.JtJ, damping.any ? &damping.D : nullptr, free);
    if (damping.any) cache.D = damping.D;
    cache.damped = damping.any;
    cache.free = free;
    cache.factored = true;
    cache.slopeValid = false;
}

void Corrector::predictStart(const AxisVector& cNom, const AxisVector& cNomPrev, const AxisVector& deltaPrev,
                             double toolLength, AxisVector& start) {
    start = cNom + deltaPrev;
    JacobianCache& cache = cache_;
    if (identity_) return;
    const int n = static_cast<int>(cNom.size());
    AxisVector scratch;
    if (!cache.slopeValid && cache.factored && cacheUsable(cache, model(cNom, scratch), toolLength)) {
        PoseJacobian Jn;
        Vec3 tip, axis;
        // The nominal machine where it was aimed: the kept commands less the correction (its Jacobian differs from
        // the erroneous one at the same commands by the deviations, and from itself at cNom by the correction's
        // turn — both of the same order).
        nominal_.jacobian(nominalData_, cache.q - deltaPrev, toolLength, Jn, tip, axis);
        Jn.bottomRows<3>() *= options_.axisWeight;
        cache.slope.resize(n, n);
        for (int i = 0; i < n; ++i)
            for (int j = 0; j < n; ++j) {
                double v = 0;
                for (int r = 0; r < 6; ++r) v += cache.normal.gain(i, r) * (Jn(r, j) - cache.J(r, j));
                cache.slope(i, j) = v;
            }
        cache.slopeValid = cache.slopeKnown = true;
        cache.slopeLength = toolLength;
    }
    // A slope from a Jacobian kept further away (before the refresh that is due) is still far better than none.
    // Not near a singular pose: there the damped solution is not a smooth function of cNom (and the slope of the
    // undamped one is large), the start stays at the neighbour's correction.
    if (!cache.slopeKnown || cache.slopeLength != toolLength || lastDamped_) return;
    double step[kMaxAxes];
    for (int j = 0; j < n; ++j) step[j] = cNom[j] - cNomPrev[j];
    switch (n) {  // unrolled for the usual axis counts (the same sums in the same order)
        case 5: addSlopeStep<5>(cache.slope, step, start); return;
        case 6: addSlopeStep<6>(cache.slope, step, start); return;
        case 4: addSlopeStep<4>(cache.slope, step, start); return;
        default: addSlopeStep<0>(cache.slope, step, start, n); return;
    }
}

bool Corrector::factorUsable(const JacobianCache& cache, const Damping& damping, AxisMask free) const {
    if (!cache.factored || cache.free != free) return false;
    if (!damping.any && !cache.damped) return true;
    // The damping enters the fixed point through the gradient exactly; the factorisation only sets the rate, so a
    // close one is kept (a changed damping near a singular pose refactors).
    if (!damping.any) return false;  // cache.damped: D ≠ 0 against none (diff > 0.1 · 0)
    if (!cache.damped) return false;  // none against D ≠ 0
    const double size = damping.D.cwiseAbs().maxCoeff();
    const double diff = (damping.D - cache.D).cwiseAbs().maxCoeff();
    return diff <= 0.1 * size;
}

void Corrector::dampingFor(const AxisVector& cNom, double toolLength, AxisMask free, const AxisVector* neighbourDelta,
                           Damping& damping, AxisVector& reference) {
    const int n = static_cast<int>(cNom.size());
    damping.any = false;  // D is read only when `any`; it is zeroed below before the first term is added
    reference = cNom;
    const AxisMask axes = free & rotary_;
    if (axes == 0) return;
    // Conditioning of the orientation: singular values of the tool axis' derivatives by the rotary axes (rad/rad,
    // the sine of the angle between the tool axis and a rotary axis for one axis). First estimated from the kept
    // Jacobian of the erroneous machine near this point; where that is clearly well conditioned, nothing is damped.
    const double s0 = options_.singularSine;
    AxisConditioning& cond = conditioning_;
    if (cache_.valid && cache_.toolLength == toolLength) {
        // The reference: the kept Jacobian of the erroneous machine (once per kept Jacobian), or the nominal one of
        // the last exact evaluation below, whichever is newer. Turning rotary axis j by δⱼ turns each column (a unit
        // rotary direction × the tool axis) by at most 2|δⱼ|, so the singular values at cNom differ from the
        // reference's by at most 2√k Σ|δⱼ| plus the deviations' share (≪ 0.01 rad).
        if (cache_.sigmaFree != free) {
            cond.compute(cache_.J, axes, 1.0 / (options_.axisWeight * options_.axisWeight), false);
            cache_.sigma = cond.smallestSingularValue();
            cache_.sigmaFree = free;
            cache_.sigmaQ = cache_.q;
        }
        double moved = 0;
        int k = 0;
        for (int i = 0; i < n; ++i)
            if (axes & (1u << i)) moved += std::fabs(cache_.sigmaQ[i] - (cNom[i] + zero_[i])), ++k;
        if (cache_.sigma >= s0 + kTwoRootOf[k] * moved + 0.01) return;
    }
    // The nominal machine's at the target, exactly: the one singular-pose policy (pose_solver.hpp), D = λ² Σ φ(σᵢ) vᵢ vᵢᵀ,
    // φ(σ) = (1 − σ/σ0)² below σ0 and 0 above, λ² = rotaryDamping² + continuity², so that damping and continuity act
    // only in the ill-conditioned directions and fade smoothly into the exact solution.
    PoseJacobian Jn;
    Vec3 tip, axis;
    nominal_.jacobian(nominalData_, cNom + zero_, toolLength, Jn, tip, axis);
    cond.compute(Jn, axes, 1.0, true);
    if (cache_.valid && cache_.toolLength == toolLength && cache_.sigmaFree == free) {  // the newer reference
        cache_.sigma = cond.smallestSingularValue();
        cache_.sigmaQ = cNom + zero_;
    }
    const double lp2 = options_.rotaryDamping * options_.rotaryDamping;
    const double lc2 = neighbourDelta ? options_.continuity * options_.continuity : 0.0;
    const double lam2 = lp2 + lc2;
    damping.any = singularDamping({std::sqrt(lam2), s0}, cond, n, damping.D);
    // Two pulls on the rotary corrections d = c − cNom in the damped directions: λp²|d|² + λc²|d − dNeighbour|² =
    // (λp² + λc²)|d − dRef|² + const, dRef = λc² dNeighbour / (λp² + λc²).
    if (damping.any && neighbourDelta)
        for (int i = 0; i < n; ++i)
            if (axes & (1u << i)) reference[i] += (lc2 / lam2) * (*neighbourDelta)[i];
}

SolveResult Corrector::solveOn(const KinematicsModel& k, KinematicsData& kd, JacobianCache& cache, const Vec3& targetTip,
                               const Vec3& targetAxis, double toolLength, const AxisVector& start,
                               const AxisVector& reference, const Damping& damping, AxisMask free,
                               AxisVector& c) {
    SolveResult res;
    const int n = static_cast<int>(start.size());
    AxisVector q = start, refScratch;
    if (!zeroIsZero_) q += zero_;
    const AxisVector& ref = model(reference, refScratch);
    const double w = options_.axisWeight;
    Eigen::Matrix<double, 6, 1> r;
    AxisVector step(n), offset(n);
    // The kept Jacobian is usable at the start: solve() refreshed it there when it was not.
    bool fresh = cache.q == q;  // evaluated at this very start (by solve())
    if (!factorUsable(cache, damping, free)) factor(cache, damping, free);
    double lastStep = HUGE_VAL, linStep = 0.0, rotStep = 0.0;
    auto newtonStep = [&]() {
        // step = A⁻¹ (Jᵀ r − D (q − ref)) (pose_solver.hpp); fixed axes have zero rows in A⁻¹ Jᵀ.
        if (damping.any) offset = q - ref;
        cache.normal.step(r, damping.any ? &damping.D : nullptr, offset, free, step);
        linStep = rotStep = 0.0;
        for (int i = 0; i < n; ++i) {
            if (rotary_ & (1u << i)) rotStep = std::max(rotStep, std::fabs(step[i]));
            else linStep = std::max(linStep, std::fabs(step[i]));
        }
        return linStep + 100.0 * rotStep;
    };
    Vec3 tip, axis;
    // The residuals' norms are taken once after the loop, of the last evaluation's squares (a square root's latency
    // stood on the loop's path; `norm` is the square root of `squaredNorm`, so the values are the same).
    double tip2 = 0.0, axis2 = 0.0;
    bool evaluated = false;
    for (res.iterations = 0; res.iterations < options_.maxIterations; ++res.iterations) {
        k.toolPoseOnce(kd, q, toolLength, tip, axis);
        const Vec3 et = targetTip - tip, ea = targetAxis - axis;
        for (int j = 0; j < 3; ++j) r[j] = et[j], r[3 + j] = ea[j] * w;
        tip2 = et.squaredNorm();
        axis2 = ea.squaredNorm();
        evaluated = true;
        if (!std::isfinite(tip2)) break;
        double size = newtonStep();
        // Chord method: the kept Jacobian while the steps shrink fast, a fresh one when they do not.
        if (!fresh && size > 0.25 * lastStep) {
            refreshJacobian(k, kd, cache, q, toolLength);
            factor(cache, damping, free);
            fresh = true;
            size = newtonStep();
        }
        lastStep = size;
        for (int i = 0; i < n; ++i) q[i] += step[i];
        if (linStep <= options_.solveTolerance && rotStep <= 1e-2 * options_.solveTolerance) {
            // The residual before this last (tiny) step bounds the one after it.
            res.converged = true;
            ++res.iterations;
            break;
        }
    }
    if (evaluated) {
        res.tipError = std::sqrt(tip2);
        res.axisError = std::sqrt(axis2);
    }
    if (!std::isfinite(res.tipError) || !allFinite(q)) {
        res.converged = false;
        cache.valid = false;
        cache.factored = false;
        cache.slopeKnown = false;
    }
    c = q;
    if (!zeroIsZero_) c -= zero_;
    return res;
}

SolveResult Corrector::solve(const AxisVector& cNom, double toolLength, const AxisVector& start, AxisVector& c,
                             const AxisVector* neighbourDelta, const Vec3& tipShift, const NominalPose* target) {
    const int n = static_cast<int>(cNom.size());
    if (identity_) {
        c = cNom;
        SolveResult res;
        res.converged = true;
        return res;
    }
    AxisMask free = (1u << n) - 1u;
    AxisVector s = start;
    if (options_.tipOnly) {
        free &= ~rotary_;
        for (int i = 0; i < n; ++i)
            if (rotary_ & (1u << i)) s[i] = cNom[i];
    }
    // The kept Jacobian near the start first: it tells whether the pose is well conditioned (no damping at all).
    AxisVector scratch;
    const AxisVector& sModel = model(s, scratch);
    if (!cacheUsable(cache_, sModel, toolLength)) refreshJacobian(actual_, actualData_, cache_, sModel, toolLength);
    Damping damping;
    AxisVector reference;
    dampingFor(cNom, toolLength, free, neighbourDelta, damping, reference);
    lastDamped_ = damping.any;
    Vec3 tip, axis;
    if (target && target->known) {  // the tool point moves along the axis with the length (toolPose is affine in it)
        tip = target->tip + (toolLength - target->length) * target->axis;
        axis = target->axis;
    } else {
        nominal_.toolPose(nominalData_, cNom + zero_, toolLength, tip, axis);
    }
    return solveOn(actual_, actualData_, cache_, tip + tipShift, axis, toolLength, s, reference, damping, free, c);
}

SolveResult Corrector::correct(const MoveSpace& s, const ProgramPoint& nominal, const AxisVector& guess,
                               const AxisVector& start, const AxisVector* neighbourDelta, AxisVector& cNom, AxisVector& c,
                               ProgramPoint& out, const Vec3& tipShift) {
    SolveResult res;
    if (!toJoints(s, nominal, guess, cNom)) {
        c = guess;
        out = nominal;
        return res;  // not converged
    }
    if (identity_) {
        c = cNom;
        out = nominal;
        res.converged = true;
        return res;
    }
    res = solve(cNom, s.toolLength, start, c, neighbourDelta, tipShift);
    toProgram(s, c, out);
    if (s.mode == ProgramMode::TcpVector && options_.tipOnly) out.v = nominal.v;
    return res;
}

Vec3 Corrector::nominalTipOf(const MoveSpace& s, const ProgramPoint& p) {
    if (s.mode == ProgramMode::Joints) return nominalTip(p.p, s.toolLength);
    // TCP: the programmed point is the controlled point (world frame), the nominal tip lies along the tool axis from
    // it; the axis depends on the rotary angles only (or is the programmed vector). No inverse kinematics needed.
    const int* lin = tcp_.linearAxes();
    const Vec3 point = tcp_.pointFromWorld(Vec3(p.p[lin[0]], p.p[lin[1]], p.p[lin[2]]));
    if (s.toolLength == s.controlLength) return point;
    Vec3 axis;
    if (s.mode == ProgramMode::TcpVector) {
        axis = tcp_.axisFromWorld(p.v.normalized());
    } else {
        AxisVector scratch;
        axis = nominal_.toolAxisOnce(nominalData_, model(p.p, scratch));
    }
    return point + (s.toolLength - s.controlLength) * axis;
}

double Corrector::deviationAt(const PathContext& ctx, const ProgramPoint& nominal, const ProgramPoint& corrected,
                              double t) {
    AxisVector cc;
    if (!toJoints(ctx.space, corrected, ctx.guess, cc)) return HUGE_VAL;
    const Vec3 e = actualTip(cc, ctx.space.toolLength) - nominalTipOf(ctx.space, nominal) - (1.0 - t) * ctx.startOffset;
    return e.norm();
}

void Corrector::correctedAt(const MovePath& path, const PathContext& ctx, double t, const ProgramPoint& near,
                            ProgramPoint& out, SplitStats& stats) {
    ProgramPoint pn;
    path.at(t, pn);
    AxisVector cNom, c, start;
    if (!toJoints(ctx.space, near, ctx.guess, start)) start = ctx.guess;
    if (!toJoints(ctx.space, pn, ctx.guess, cNom)) cNom = start;
    // The rotary corrections of the interpolation between the corrected ends are this point's neighbours.
    const AxisVector neighbour = start - cNom;
    // On the path with the start offset blended out, like every check.
    correct(ctx.space, pn, ctx.guess, start, &neighbour, cNom, c, out, (1.0 - t) * ctx.startOffset);
    ++stats.solves;
}

void Corrector::split(const MovePath& path, const PathContext& ctx, const ProgramPoint& end, bool subdivide,
                      std::vector<Piece>& pieces, SplitStats& stats) {
    if (identity_) {
        pieces.push_back({1.0, end});
        return;
    }
    if (ctx.midpointBound < ctx.tolerance && ctx.midpointBound < ctx.largestMeasured) {
        // The midpoint's deviation is at most the bound: the check would keep the move whole and leave the largest
        // deviation reported as it is. Not evaluated.
        pieces.push_back({1.0, end});
        stats.bounded = true;
        return;
    }
    if (affine_ && !path.circular && !path.vector) {
        // Location errors only and no rotary motion: the actual tip is an affine function of the linear axes (of the
        // world point, in TCP mode), so straight interpolation of corrected end points stays on the nominal line
        // (with a start offset blended out linearly); nothing to check.
        bool rotaryFixed = true;
        for (int i = 0; i < path.start.size() && rotaryFixed; ++i)
            if (rotary_ & (1u << i))
                rotaryFixed = path.start[i] == path.end[i] && std::fabs(ctx.outStart.p[i] - end.p[i]) < 1e-6;
        if (rotaryFixed) {
            pieces.push_back({1.0, end});
            return;
        }
    }
    if (!subdivide) {
        ProgramPoint pn, pc;
        path.at(0.5, pn);
        lerpPoint(ctx.outStart, end, 0.5, path.vector, pc);
        stats.maxDeviation = std::max(stats.maxDeviation, deviationAt(ctx, pn, pc, 0.5));
        pieces.push_back({1.0, end});
        return;
    }
    splitRecursive(path, ctx, 0.0, ctx.outStart, 1.0, end, 0, pieces, stats);
}

void Corrector::splitRecursive(const MovePath& path, const PathContext& ctx, double t0, const ProgramPoint& q0,
                               double t1, const ProgramPoint& q1, int depth, std::vector<Piece>& pieces,
                               SplitStats& stats) {
    const double tm = 0.5 * (t0 + t1);
    ProgramPoint pn, pc;
    path.at(tm, pn);
    lerpPoint(q0, q1, 0.5, path.vector, pc);
    const double dev = deviationAt(ctx, pn, pc, tm);
    if (dev <= ctx.tolerance || depth >= options_.maxDepth || static_cast<int>(pieces.size()) + 2 > options_.maxPieces) {
        if (dev > ctx.tolerance) stats.limited = true;
        stats.maxDeviation = std::max(stats.maxDeviation, dev);
        pieces.push_back({t1, q1});
        return;
    }
    ProgramPoint qm;
    correctedAt(path, ctx, tm, pc, qm, stats);
    splitRecursive(path, ctx, t0, q0, tm, qm, depth + 1, pieces, stats);
    splitRecursive(path, ctx, tm, qm, t1, q1, depth + 1, pieces, stats);
}

ArcFit Corrector::fitArc(const MovePath& path, const PathContext& ctx, const ProgramPoint& end, bool closed) {
    ArcFit fit;
    const int a0 = path.axis0, a1 = path.axis1;
    if (identity_) {
        fit.ok = true;
        fit.c0 = path.c0;
        fit.c1 = path.c1;
        fit.sweep = path.sweep;
        return fit;
    }
    // Correction at the centre (other coordinates at mid-move): the corrected arc's centre.
    ProgramPoint pc, pcStar;
    path.at(0.5, pc);
    pc.p[a0] = path.c0;
    pc.p[a1] = path.c1;
    {
        AxisVector cNom, c, start;
        if (!toJoints(ctx.space, pc, ctx.guess, start)) return fit;
        correct(ctx.space, pc, ctx.guess, start, nullptr, cNom, c, pcStar, 0.5 * ctx.startOffset);
    }
    double c0 = pcStar.p[a0], c1 = pcStar.p[a1];
    // Onto the bisector of the corrected end points, so that start and end radius agree.
    const AxisVector& outStart = ctx.outStart.p;
    const double s0 = outStart[a0], s1 = outStart[a1], e0 = end.p[a0], e1 = end.p[a1];
    const double d0 = e0 - s0, d1 = e1 - s1, d = std::hypot(d0, d1);
    if (!closed && d > 1e-9) {
        const double u0 = d0 / d, u1 = d1 / d, m0 = 0.5 * (s0 + e0), m1 = 0.5 * (s1 + e1);
        const double along = (c0 - m0) * u0 + (c1 - m1) * u1;
        c0 -= along * u0;
        c1 -= along * u1;
    }
    const double r = std::hypot(s0 - c0, s1 - c1);
    const double th0 = std::atan2(s1 - c1, s0 - c0), th1 = std::atan2(e1 - c1, e0 - c0);
    double sweep;
    if (closed) {
        sweep = path.sweep;
    } else {
        sweep = th1 - th0;
        // Same turning sense and number of turns as the nominal arc.
        const double turns = std::floor(std::fabs(path.sweep) / kTwoPi);
        if (path.sweep < 0) {
            while (sweep >= 0) sweep -= kTwoPi;
            while (sweep < -kTwoPi) sweep += kTwoPi;
            sweep -= kTwoPi * turns;
        } else {
            while (sweep <= 0) sweep += kTwoPi;
            while (sweep > kTwoPi) sweep -= kTwoPi;
            sweep += kTwoPi * turns;
        }
        if (std::fabs(sweep - path.sweep) > 0.5) return fit;  // the correction would change the arc's sense
    }
    fit.c0 = c0;
    fit.c1 = c1;
    fit.sweep = sweep;
    const int samples = std::max(4, static_cast<int>(std::ceil(std::fabs(sweep) / (kPi / 8))));
    ProgramPoint pn, po;
    for (int k = 0; k < samples; ++k) {
        const double t = (k + 0.5) / samples;
        path.at(t, pn);
        lerpPoint(ctx.outStart, end, t, path.vector, po);
        const double th = th0 + t * sweep;
        po.p[a0] = c0 + r * std::cos(th);
        po.p[a1] = c1 + r * std::sin(th);
        fit.maxDeviation = std::max(fit.maxDeviation, deviationAt(ctx, pn, po, t));
    }
    fit.ok = fit.maxDeviation <= ctx.tolerance;
    return fit;
}

void Corrector::splitArc(const MovePath& path, const PathContext& ctx, const ProgramPoint& end,
                         std::vector<Piece>& pieces, SplitStats& stats) {
    // Chords whose sagitta stays below half the tolerance; the midpoint checks split further where needed.
    const double r = std::max(path.r0, path.r1);
    const double tol = ctx.tolerance * 0.5;
    int chords = 1;
    if (r > tol) {
        const double maxAngle = 2.0 * std::acos(1.0 - tol / r);
        chords = static_cast<int>(std::ceil(std::fabs(path.sweep) / maxAngle));
    }
    chords = std::clamp(chords, 2, std::max(2, options_.maxPieces / 2));
    ProgramPoint q0 = ctx.outStart, q1, pn;
    for (int k = 1; k <= chords; ++k) {
        const double t0 = static_cast<double>(k - 1) / chords, t1 = static_cast<double>(k) / chords;
        if (k == chords) {
            q1 = end;
        } else {
            path.at(t1, pn);
            ProgramPoint near = pn;
            near.p += end.p - path.end;
            correctedAt(path, ctx, t1, near, q1, stats);
        }
        splitRecursive(path, ctx, t0, q0, t1, q1, 0, pieces, stats);
        q0 = q1;
    }
}

}  // namespace cnccomp::postproc
