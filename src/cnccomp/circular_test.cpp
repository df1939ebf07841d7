#include "cnccomp/identification/dbb5_circular.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/QR>

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

}  // namespace cnccomp
