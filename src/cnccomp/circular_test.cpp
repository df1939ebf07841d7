#include "cnccomp/circular_test.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include <Eigen/QR>
#include <fmt/format.h>

#include "cnccomp/circle_fit.hpp"
#include "cnccomp/error.hpp"

namespace cnccomp {

CircularTestResult evaluateCircularTest(const BallbarTrace& trace, double LB) {
    const size_t n = trace.dL.size();
    if (trace.angleDeg.size() != n) throw ModelError("circular test: angle and ΔL counts differ");
    if (n < 5) throw ModelError("circular test: at least five samples are needed");
    if (!(LB > 0) || !std::isfinite(LB)) throw ModelError("circular test: LB must be a positive number");
    CircularTestResult r;
    r.samples = static_cast<int>(n);
    std::vector<Eigen::Vector2d> pts;
    pts.reserve(n);
    Eigen::MatrixXd A(static_cast<Eigen::Index>(n), 5);
    Eigen::VectorXd y(static_cast<Eigen::Index>(n));
    for (size_t i = 0; i < n; ++i) {
        const double a = trace.angleDeg[i] * kDeg, d = trace.dL[i];
        if (!std::isfinite(a) || !std::isfinite(d)) throw ModelError("circular test: samples must be finite numbers");
        pts.emplace_back((LB + d) * std::cos(a), (LB + d) * std::sin(a));
        const auto row = static_cast<Eigen::Index>(i);
        A.row(row) << 1.0, std::cos(a), std::sin(a), std::cos(2 * a), std::sin(2 * a);
        y[row] = d;
    }
    const CircleFit c = fitCircle(pts);
    r.center = c.center;
    r.meanRadialError = c.radius - LB;
    r.meanRadius = c.radius;
    double lo = HUGE_VAL, hi = -HUGE_VAL;
    for (const auto& p : pts) {
        const double d = (p - c.center).norm();
        lo = std::min(lo, d);
        hi = std::max(hi, d);
    }
    r.circularity = hi - lo;
    r.radialMax = *std::max_element(trace.dL.begin(), trace.dL.end());
    r.radialMin = *std::min_element(trace.dL.begin(), trace.dL.end());
    double sum = 0;
    for (double d : trace.dL) sum += d;
    r.meanDeltaL = sum / static_cast<double>(n);
    Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(A);
    if (qr.rank() == 5) {
        const Eigen::VectorXd f = qr.solve(y);
        r.a0 = f[0];
        r.a1 = f[1];
        r.b1 = f[2];
        r.a2 = f[3];
        r.b2 = f[4];
    } else {
        r.a0 = r.a1 = r.b1 = r.a2 = r.b2 = std::numeric_limits<double>::quiet_NaN();
    }
    return r;
}

namespace {

/// ΔL of `t` interpolated linearly at `angle` (deg); `order` sorts t by angle. False outside its range.
bool interpolate(const BallbarTrace& t, const std::vector<size_t>& order, double angle, double& out) {
    const double lo = t.angleDeg[order.front()], hi = t.angleDeg[order.back()];
    if (angle < lo || angle > hi) return false;
    const auto it = std::lower_bound(order.begin(), order.end(), angle,
                                     [&](size_t i, double a) { return t.angleDeg[i] < a; });
    const size_t k = static_cast<size_t>(it - order.begin());
    if (k == 0) {
        out = t.dL[order[0]];
        return true;
    }
    const size_t i0 = order[k - 1], i1 = order[k];
    const double a0 = t.angleDeg[i0], a1 = t.angleDeg[i1];
    const double f = a1 > a0 ? (angle - a0) / (a1 - a0) : 1.0;
    out = t.dL[i0] + f * (t.dL[i1] - t.dL[i0]);
    return true;
}

std::vector<size_t> byAngle(const BallbarTrace& t) {
    std::vector<size_t> order(t.angleDeg.size());
    std::iota(order.begin(), order.end(), size_t{0});
    std::stable_sort(order.begin(), order.end(), [&](size_t i, size_t j) { return t.angleDeg[i] < t.angleDeg[j]; });
    return order;
}

}  // namespace

double circularHysteresis(const BallbarTrace& a, const BallbarTrace& b, int* compared) {
    if (compared) *compared = 0;
    if (a.dL.empty() || b.dL.empty() || a.dL.size() != a.angleDeg.size() || b.dL.size() != b.angleDeg.size())
        return std::numeric_limits<double>::quiet_NaN();
    const std::vector<size_t> oa = byAngle(a), ob = byAngle(b);
    double h = -1;
    int n = 0;
    const auto scan = [&](const BallbarTrace& from, const BallbarTrace& other, const std::vector<size_t>& oOther) {
        for (size_t i = 0; i < from.dL.size(); ++i) {
            double v = 0;
            if (!interpolate(other, oOther, from.angleDeg[i], v)) continue;
            h = std::max(h, std::abs(from.dL[i] - v));
            ++n;
        }
    };
    scan(a, b, ob);
    scan(b, a, oa);
    if (compared) *compared = n;
    return n > 0 ? h : std::numeric_limits<double>::quiet_NaN();
}

CircularRunResult evaluateCircularRun(const std::vector<DirectedTrace>& passes, double LB) {
    if (passes.empty()) throw ModelError("circular test: a run needs at least one pass");
    CircularRunResult r;
    double radii = 0;
    for (const DirectedTrace& p : passes) {
        if (p.direction != 1 && p.direction != -1)
            throw ModelError(fmt::format("circular test: pass direction {} is not +1 (CCW) or -1 (CW)", p.direction));
        const CircularTestResult e = evaluateCircularTest(p.trace, LB);
        if (r.passes.empty()) {
            r.radialMax = e.radialMax;
            r.radialMin = e.radialMin;
        }
        r.circularDeviation = std::max(r.circularDeviation, e.circularity);
        r.radialMax = std::max(r.radialMax, e.radialMax);
        r.radialMin = std::min(r.radialMin, e.radialMin);
        radii += e.meanRadius;
        r.passes.push_back(e);
        r.directions.push_back(p.direction);
    }
    r.meanRadius = radii / static_cast<double>(passes.size());
    // H from the first CCW and the first CW pass.
    const DirectedTrace *ccw = nullptr, *cw = nullptr;
    for (const DirectedTrace& p : passes) {
        if (p.direction > 0 && !ccw) ccw = &p;
        if (p.direction < 0 && !cw) cw = &p;
    }
    if (ccw && cw) r.hysteresis = circularHysteresis(ccw->trace, cw->trace, &r.hysteresisSamples);
    return r;
}

}  // namespace cnccomp
