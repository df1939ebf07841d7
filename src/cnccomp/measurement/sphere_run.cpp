#include "cnccomp/measurement/sphere_run.hpp"

#include <cmath>
#include <set>

#include <fmt/format.h>

#include "cnccomp/error.hpp"

namespace cnccomp::measurement {

void SphereRun::validate() const {
    const auto bad = [&](const std::string& what) { throw ModelError(fmt::format("sphere run '{}': {}", name, what)); };
    if (!centre.allFinite() || !sphereOffset.allFinite()) bad("centre and sphere-offset must be finite numbers");
    const auto positive = [&](double v, const char* what) {
        if (!(v > 0) || !std::isfinite(v)) bad(fmt::format("{} must be a positive number of mm", what));
    };
    positive(diameter, "diameter");
    positive(stylusDiameter, "stylus-diameter");
    positive(approach, "approach");
    positive(feed, "feed (mm/min)");
    positive(clearance, "clearance");
    if (!std::isfinite(toolLength)) bad("tool-length must be a finite number");
    if (window == window) positive(window, "window");
    if (clearance < approach) bad("clearance must be at least the approach distance");
    if (!std::isfinite(triggerOffset) || !std::isfinite(triggerError) || std::abs(triggerOffset) >= 0.25 * stylusDiameter)
        bad("trigger-offset must be a finite number smaller than a quarter of the stylus diameter");
    if (approach >= 0.5 * (diameter + stylusDiameter)) bad("approach must be smaller than the sphere and stylus radii together");
    if (!(latitudeDeg >= 0 && latitudeDeg <= 60)) bad("latitude must be 0 .. 60 deg");
    if (ringTouches < 4 || ringTouches > 64) bad("ring touches must be 4 .. 64 (the pole and at least four at the latitude)");
    if (groups.empty()) bad("no pose (give <sweep>/<hold>, <group> or <pose> children)");
    for (const SpherePoseGroup& g : groups) {
        std::set<std::string> axes;
        bool moving = false;
        for (const RotarySweep& s : g.sweeps) {
            if (!std::isfinite(s.startDeg) || !std::isfinite(s.endDeg)) bad(fmt::format("axis {}: angles must be finite", s.axis));
            if (!axes.insert(s.axis).second) bad(fmt::format("axis {} is given twice in one group of poses", s.axis));
            if (s.startDeg != s.endDeg) moving = true;
        }
        if (g.steps < 0 || g.steps > 10000) bad("steps must be 1 .. 10000");
        if (g.steps == 0 && moving) bad("a sweep needs steps (the number of intervals)");
        if (g.steps > 0 && !moving) bad("a group with steps needs a sweep whose start and end differ");
    }
}

std::vector<SpherePose> SphereRun::poses() const {
    std::vector<SpherePose> out;
    for (const SpherePoseGroup& g : groups) {
        if (g.steps == 0) {
            SpherePose p;
            for (const RotarySweep& s : g.sweeps) p.emplace_back(s.axis, s.startDeg);
            out.push_back(p);
            continue;
        }
        // As RtestRun::sampleCount: a sweep in which every moving axis turns by whole turns does not repeat its start.
        bool closed = true;
        for (const RotarySweep& s : g.sweeps) {
            const double span = std::abs(s.endDeg - s.startDeg);
            if (span == 0) continue;
            if (span < 360.0 - 1e-9 || std::abs(std::remainder(span, 360.0)) > 1e-9) closed = false;
        }
        const int n = g.steps + (closed ? 0 : 1);
        for (int i = 0; i < n; ++i) {
            SpherePose p;
            for (const RotarySweep& s : g.sweeps) p.emplace_back(s.axis, s.startDeg + (s.endDeg - s.startDeg) * i / g.steps);
            out.push_back(p);
        }
    }
    return out;
}

}  // namespace cnccomp::measurement
