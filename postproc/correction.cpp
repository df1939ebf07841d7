#include "postproc/correction.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>

namespace cnccomp::pp {

namespace {
constexpr double kTwoPi = 2.0 * kPi;
}  // namespace

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

void MovePath::at(double t, AxisVector& q) const {
    q = start + t * (end - start);
    if (!circular) return;
    const double th = theta0 + t * sweep, r = r0 + t * (r1 - r0);
    q[axis0] = c0 + r * std::cos(th);
    q[axis1] = c1 + r * std::sin(th);
}

Corrector::Corrector(const MachineModel& machine, const DeviationSet& deviations, const CorrectorOptions& options)
    : machine_(machine), nominal_(machine), actual_(machine, deviations), options_(options) {
    identity_ = deviations.values.size() == 0 || deviations.values.cwiseAbs().maxCoeff() == 0.0;
    affine_ = true;
    for (const DeviationDef& d : machine.deviations)
        if (d.kind == DeviationKind::Component)
            for (int k = 0; k < d.size(); ++k)
                if (deviations.values[d.offset + k] != 0.0) affine_ = false;
    for (int i = 0; i < machine.axisCount(); ++i)
        if (machine.axisLink(i).kind == AxisKind::Rotary) rotary_ |= 1u << i;
}

double Corrector::tipDeviation(const AxisVector& qNom, const AxisVector& q, double toolLength) const {
    const Vec3 tip = nominal_.toolPoint(toolLength);
    const Vec3 a = nominal_.toolPointInWorkpiece(qNom, tip);
    const Vec3 b = actual_.toolPointInWorkpiece(q, tip);
    return (a - b).norm();
}

bool Corrector::cacheUsable(const AxisVector& q, double toolLength) const {
    if (!cache_.valid || cache_.toolLength != toolLength || cache_.q.size() != q.size()) return false;
    for (int i = 0; i < q.size(); ++i) {
        const double d = std::fabs(q[i] - cache_.q[i]);
        if ((rotary_ & (1u << i)) ? d > 0.5 * kDeg : d > 10.0) return false;
    }
    return true;
}

void Corrector::refreshJacobian(const AxisVector& q, double toolLength, const Vec3& tip) const {
    const int n = static_cast<int>(q.size());
    const double w = options_.axisWeight, lam2 = options_.rotaryDamping * options_.rotaryDamping;
    AxisMask free = (1u << n) - 1u;
    if (options_.tipOnly) free &= ~rotary_;
    toolPoseJacobian(actual_, q, tip, cache_.J);
    cache_.J.bottomRows<3>() *= w;
    cache_.A.resize(n, n);
    cache_.A.noalias() = cache_.J.transpose() * cache_.J;
    for (int i = 0; i < n; ++i) {
        if (!(free & (1u << i))) {
            cache_.A.row(i).setZero();
            cache_.A.col(i).setZero();
            cache_.A(i, i) = 1.0;
        } else if (rotary_ & (1u << i)) {
            cache_.A(i, i) += lam2;
        }
        cache_.A(i, i) += 1e-12 * (1.0 + cache_.A(i, i));
    }
    // n ≤ 9: an explicit inverse makes every chord step two small matrix-vector products.
    cache_.Ainv = cache_.A.llt().solve(decltype(cache_.A)::Identity(n, n));
    cache_.gain.noalias() = cache_.Ainv * cache_.J.transpose();
    cache_.q = q;
    cache_.toolLength = toolLength;
    cache_.valid = true;
}

SolveResult Corrector::solve(const AxisVector& qNom, double toolLength, const AxisVector& start, AxisVector& q) const {
    SolveResult res;
    const int n = static_cast<int>(qNom.size());
    q = start;
    if (identity_) {
        q = qNom;
        res.converged = true;
        return res;
    }
    const Vec3 tip = nominal_.toolPoint(toolLength);
    const ToolPose target = toolPose(nominal_, qNom, tip);
    const double w = options_.axisWeight, lam2 = options_.rotaryDamping * options_.rotaryDamping;
    AxisMask free = (1u << n) - 1u;
    if (options_.tipOnly) {
        free &= ~rotary_;
        for (int i = 0; i < n; ++i)
            if (rotary_ & (1u << i)) q[i] = qNom[i];
    }
    AxisVector g(n), step(n);
    Eigen::Matrix<double, 6, 1> r;
    bool fresh = false;
    if (!cacheUsable(q, toolLength)) {
        refreshJacobian(q, toolLength, tip);
        fresh = true;
    }
    double lastStep = HUGE_VAL, linStep = 0.0, rotStep = 0.0;
    auto newtonStep = [&]() {
        // step = A⁻¹ (Jᵀ r − λ² S (q − qNom)); fixed axes have zero rows in A⁻¹ Jᵀ.
        step.noalias() = cache_.gain * r;
        for (int i = 0; i < n; ++i) g[i] = (free & rotary_ & (1u << i)) ? lam2 * (q[i] - qNom[i]) : 0.0;
        if (rotary_ & free) step.noalias() -= cache_.Ainv * g;
        for (int i = 0; i < n; ++i)
            if (!(free & (1u << i))) step[i] = 0.0;
        linStep = rotStep = 0.0;
        for (int i = 0; i < n; ++i) {
            if (rotary_ & (1u << i)) rotStep = std::max(rotStep, std::fabs(step[i]));
            else linStep = std::max(linStep, std::fabs(step[i]));
        }
        return linStep + 100.0 * rotStep;
    };
    for (res.iterations = 0; res.iterations < options_.maxIterations; ++res.iterations) {
        const ToolPose p = toolPose(actual_, q, tip);
        r.head<3>() = target.tip - p.tip;
        r.tail<3>() = (target.axis - p.axis) * w;
        res.tipError = r.head<3>().norm();
        res.axisError = (target.axis - p.axis).norm();
        if (!std::isfinite(res.tipError)) break;
        double size = newtonStep();
        // Chord method: the kept Jacobian while the steps shrink fast, a fresh one when they do not.
        if (!fresh && size > 0.25 * lastStep) {
            refreshJacobian(q, toolLength, tip);
            fresh = true;
            size = newtonStep();
        }
        lastStep = size;
        q += step;
        if (linStep <= options_.solveTolerance && rotStep <= 1e-9) {
            // The residual before this last (tiny) step bounds the one after it.
            res.converged = true;
            ++res.iterations;
            break;
        }
    }
    if (!std::isfinite(res.tipError) || !q.allFinite()) {
        res.converged = false;
        cache_.valid = false;
    }
    return res;
}

void Corrector::split(const MovePath& path, const AxisVector& outStart, const AxisVector& qEnd, double toolLength,
                      bool subdivide, std::vector<Piece>& pieces, SplitStats& stats) const {
    if (identity_) {
        pieces.push_back({1.0, qEnd});
        return;
    }
    if (affine_ && !path.circular) {
        // Location errors only and no rotary motion: the actual tip is an affine function of the linear axes,
        // so straight interpolation of corrected end points stays on the nominal line; nothing to check.
        bool rotaryFixed = true;
        for (int i = 0; i < path.start.size() && rotaryFixed; ++i)
            if (rotary_ & (1u << i))
                rotaryFixed = path.start[i] == path.end[i] && std::fabs(outStart[i] - qEnd[i]) < 1e-6;
        if (rotaryFixed) {
            pieces.push_back({1.0, qEnd});
            return;
        }
    }
    if (!subdivide) {
        AxisVector qn, qo;
        path.at(0.5, qn);
        qo = 0.5 * (outStart + qEnd);
        stats.maxDeviation = std::max(stats.maxDeviation, tipDeviation(qn, qo, toolLength));
        pieces.push_back({1.0, qEnd});
        return;
    }
    splitRecursive(path, 0.0, outStart, 1.0, qEnd, toolLength, 0, pieces, stats);
}

void Corrector::splitRecursive(const MovePath& path, double t0, const AxisVector& q0, double t1, const AxisVector& q1,
                               double toolLength, int depth, std::vector<Piece>& pieces, SplitStats& stats) const {
    const double tm = 0.5 * (t0 + t1);
    AxisVector qn, qo;
    path.at(tm, qn);
    qo = 0.5 * (q0 + q1);
    const double dev = tipDeviation(qn, qo, toolLength);
    if (dev <= options_.toleranceMm || depth >= options_.maxDepth ||
        static_cast<int>(pieces.size()) + 2 > options_.maxPieces) {
        if (dev > options_.toleranceMm) stats.limited = true;
        stats.maxDeviation = std::max(stats.maxDeviation, dev);
        pieces.push_back({t1, q1});
        return;
    }
    AxisVector qm;
    solve(qn, toolLength, qo, qm);
    ++stats.solves;
    splitRecursive(path, t0, q0, tm, qm, toolLength, depth + 1, pieces, stats);
    splitRecursive(path, tm, qm, t1, q1, toolLength, depth + 1, pieces, stats);
}

ArcFit Corrector::fitArc(const MovePath& path, const AxisVector& outStart, const AxisVector& qEnd, double toolLength,
                         bool closed) const {
    ArcFit fit;
    const int a0 = path.axis0, a1 = path.axis1;
    if (identity_) {
        fit.ok = true;
        fit.c0 = path.c0;
        fit.c1 = path.c1;
        fit.sweep = path.sweep;
        return fit;
    }
    // Correction at the centre (other axes at mid-move): the corrected arc's centre.
    AxisVector qc, qcStar;
    path.at(0.5, qc);
    qc[a0] = path.c0;
    qc[a1] = path.c1;
    AxisVector start = qc + (qEnd - path.end);
    solve(qc, toolLength, start, qcStar);
    double c0 = qcStar[a0], c1 = qcStar[a1];
    // Onto the bisector of the corrected end points, so that start and end radius agree.
    const double s0 = outStart[a0], s1 = outStart[a1], e0 = qEnd[a0], e1 = qEnd[a1];
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
    AxisVector qn, qo;
    for (int k = 0; k < samples; ++k) {
        const double t = (k + 0.5) / samples;
        path.at(t, qn);
        qo = outStart + t * (qEnd - outStart);
        const double th = th0 + t * sweep;
        qo[a0] = c0 + r * std::cos(th);
        qo[a1] = c1 + r * std::sin(th);
        fit.maxDeviation = std::max(fit.maxDeviation, tipDeviation(qn, qo, toolLength));
    }
    fit.ok = fit.maxDeviation <= options_.toleranceMm;
    return fit;
}

void Corrector::splitArc(const MovePath& path, const AxisVector& outStart, const AxisVector& qEnd, double toolLength,
                         std::vector<Piece>& pieces, SplitStats& stats) const {
    // Chords whose sagitta stays below half the tolerance; the midpoint checks split further where needed.
    const double r = std::max(path.r0, path.r1);
    const double tol = options_.toleranceMm * 0.5;
    int chords = 1;
    if (r > tol) {
        const double maxAngle = 2.0 * std::acos(1.0 - tol / r);
        chords = static_cast<int>(std::ceil(std::fabs(path.sweep) / maxAngle));
    }
    chords = std::clamp(chords, 2, std::max(2, options_.maxPieces / 2));
    AxisVector q0 = outStart, qn, q1;
    for (int k = 1; k <= chords; ++k) {
        const double t0 = static_cast<double>(k - 1) / chords, t1 = static_cast<double>(k) / chords;
        if (k == chords) {
            q1 = qEnd;
        } else {
            path.at(t1, qn);
            solve(qn, toolLength, qn + (qEnd - path.end), q1);
            ++stats.solves;
        }
        splitRecursive(path, t0, q0, t1, q1, toolLength, 0, pieces, stats);
        q0 = q1;
    }
}

}  // namespace cnccomp::pp
