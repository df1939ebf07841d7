#pragma once
// The sample angles of a sweep, shared by every run kind that samples an angle at a fixed step.
#include <cmath>
#include <vector>

namespace cnccomp::measurement {

/// start, start + step, … up to `end` (degrees; the step's sign gives the direction, validated by the run). A sweep of
/// whole turns ends where it began: its last sample (the first again) is left out.
inline std::vector<double> sweepAnglesDeg(double startDeg, double endDeg, double stepDeg) {
    const double span = endDeg - startDeg;
    long n = static_cast<long>(std::floor(span / stepDeg + 1e-9)) + 1;
    const double last = startDeg + static_cast<double>(n - 1) * stepDeg;
    if (n > 1 && std::abs(span) >= 360.0 - 1e-9 && std::abs(std::remainder(last - startDeg, 360.0)) < 1e-9) --n;
    std::vector<double> a(static_cast<size_t>(n));
    for (long i = 0; i < n; ++i) a[static_cast<size_t>(i)] = startDeg + static_cast<double>(i) * stepDeg;
    return a;
}

}  // namespace cnccomp::measurement
