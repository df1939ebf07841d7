#include "cnccomp/measurement/rtest_run.hpp"

#include <cmath>
#include <set>

#include <fmt/format.h>

#include "cnccomp/error.hpp"

namespace cnccomp::measurement {

void RtestRun::validate() const {
    const auto bad = [&](const std::string& what) { throw ModelError(fmt::format("R-test run '{}': {}", name, what)); };
    if (!ball.allFinite() || !ballOffset.allFinite() || !std::isfinite(nestLength)) bad("geometry must be finite numbers");
    if (steps < 1 || steps > 1000000) bad("steps must be 1 .. 1000000");
    std::set<std::string> axes;
    bool moving = false;
    for (const RotarySweep& s : sweeps) {
        if (!std::isfinite(s.startDeg) || !std::isfinite(s.endDeg)) bad(fmt::format("axis {}: angles must be finite", s.axis));
        if (!axes.insert(s.axis).second) bad(fmt::format("axis {} is swept twice", s.axis));
        if (s.startDeg != s.endDeg) moving = true;
    }
    if (!moving) bad("no rotary axis moves (give an axis with start != end)");
}

int RtestRun::sampleCount() const {
    // A sweep in which every moving axis turns by whole turns ends where it began: drop the last pose.
    bool closed = true;
    for (const RotarySweep& s : sweeps) {
        const double span = std::abs(s.endDeg - s.startDeg);
        if (span == 0) continue;
        if (span < 360.0 - 1e-9 || std::abs(std::remainder(span, 360.0)) > 1e-9) closed = false;
    }
    return steps + (closed ? 0 : 1);
}

double RtestRun::angleDeg(int s, int i) const {
    const RotarySweep& w = sweeps[static_cast<size_t>(s)];
    return w.startDeg + (w.endDeg - w.startDeg) * i / steps;
}

}  // namespace cnccomp::measurement
