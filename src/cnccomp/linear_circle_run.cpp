#include "cnccomp/linear_circle_run.hpp"

#include <cmath>

#include <fmt/format.h>

#include "cnccomp/error.hpp"

namespace cnccomp {

void LinearCircleRun::validate() const {
    const auto bad = [&](const std::string& what) { throw ModelError(fmt::format("circle run '{}': {}", name, what)); };
    for (double v : {radius, startDeg, arcDeg, stepDeg, toolLength, capture.feed, capture.overshootDeg})
        if (!std::isfinite(v)) bad("values must be finite numbers");
    if (!centre.allFinite() || !pivotOffset.allFinite()) bad("centre and pivot offset must be finite");
    if (pivotOffset.norm() > 0.1 * radius) bad("the pivot offset is a set-up error: at most a tenth of the radius");
    if (!(radius > 0)) bad(fmt::format("radius {:g} mm: expected a positive radius (the ball-bar length)", radius));
    if (!(arcDeg > 0 && arcDeg <= 360)) bad(fmt::format("arc {:g}°: expected 0 < arc ≤ 360", arcDeg));
    if (!(stepDeg > 0)) bad(fmt::format("step {:g}°: expected a positive sample spacing", stepDeg));
    if (stepDeg > arcDeg / 8) bad(fmt::format("step {:g}° gives fewer than 8 samples on the {:g}° arc", stepDeg, arcDeg));
    if (!(capture.feed > 0)) bad("feed must be positive (mm/min)");
    if (!(capture.overshootDeg >= 0 && capture.overshootDeg <= 90)) bad("overshoot must be 0 .. 90°");
    for (double p : cyclicPitch)
        if (!(p >= 0) || !std::isfinite(p)) bad("pitch must be zero or positive (mm)");
    const std::vector<int> d = directions();
    if (d.empty() || d.size() > 2 || (d.size() == 2 && d[0] == d[1])) bad("directions must be ccw, cw, \"ccw cw\" or \"cw ccw\"");
    for (int x : d)
        if (x != 1 && x != -1) bad("a direction is +1 (CCW) or -1 (CW)");
    for (const auto& [axis, deg] : hold)
        if (!std::isfinite(deg)) bad(fmt::format("held position of {} must be finite", axis));
}

std::vector<int> LinearCircleRun::directions() const {
    return capture.passes.empty() ? std::vector<int>{-1, +1} : capture.passes;
}

std::vector<double> LinearCircleRun::dataAnglesDeg() const {
    const long n = static_cast<long>(std::floor(arcDeg / stepDeg + 1e-9));
    std::vector<double> a;
    for (long i = 0; i <= n; ++i) a.push_back(startDeg + static_cast<double>(i) * stepDeg);
    if (std::abs(a.back() - endDeg()) > 1e-9) a.push_back(endDeg());
    return a;
}

LinearCircle LinearCircleRun::circle() const {
    const std::array<char, 2> ax = linearPlaneAxes(plane);
    const auto at = [&](char c) { return centre[c - 'X']; };
    LinearCircle c;
    c.plane = plane;
    c.centre = Eigen::Vector2d(at(ax[0]), at(ax[1]));
    c.radius = radius;
    return c;
}

AxisVector linearCircleCentreCommands(const MachineModel& m, const LinearCircleRun& run) {
    AxisVector q = AxisVector::Zero(m.axisCount());
    for (const auto& [axis, deg] : run.hold) {
        const int i = m.axisIndex(axis);
        if (i < 0) throw ModelError(fmt::format("circle run '{}': machine '{}' has no axis '{}' to hold", run.name, m.name, axis));
        if (m.axisLink(i).kind != AxisKind::Rotary)
            throw ModelError(fmt::format("circle run '{}': held axis '{}' is not rotary (the centre gives the linear axes)",
                                         run.name, axis));
        q[i] = deg * kDeg;
    }
    for (int k = 0; k < 3; ++k) {
        const char name[2] = {static_cast<char>('X' + k), 0};
        const int i = m.axisIndex(name);
        if (i < 0) {
            // The axis normal to the plane may be missing only if the centre does not use it (a 2-axis machine).
            const std::array<char, 2> ax = linearPlaneAxes(run.plane);
            if (ax[0] == name[0] || ax[1] == name[0] || run.centre[k] != 0)
                throw ModelError(fmt::format("circle run '{}' in {}: machine '{}' has no linear axis {}", run.name,
                                             linearPlaneName(run.plane), m.name, name));
            continue;
        }
        if (m.axisLink(i).kind != AxisKind::Linear)
            throw ModelError(fmt::format("circle run '{}': axis {} of machine '{}' is not linear", run.name, name, m.name));
        q[i] = run.centre[k];
    }
    return q;
}

AxisVector linearCircleCommands(const MachineModel& m, const LinearCircleRun& run, double thetaDeg) {
    AxisVector q = linearCircleCentreCommands(m, run);
    const std::array<char, 2> ax = linearPlaneAxes(run.plane);
    const double t = thetaDeg * kDeg;
    q[m.requireAxis(std::string(1, ax[0]))] += run.radius * std::cos(t);
    q[m.requireAxis(std::string(1, ax[1]))] += run.radius * std::sin(t);
    return q;
}

std::vector<DirectedTrace> simulateLinearCircle(const Kinematics& k, const LinearCircleRun& run) {
    run.validate();
    const MachineModel& m = k.machine();
    const Vec3 ball = k.toolPoint(run.toolLength);
    const AxisVector qc = linearCircleCentreCommands(m, run);
    const Vec3 pivot = k.toolPointInWorkpiece(qc, ball) + run.pivotOffset;
    const double ov = run.capture.overshootDeg;
    std::vector<DirectedTrace> out;
    for (int d : run.directions()) {
        const double from = (d > 0 ? run.startDeg : run.endDeg()) - d * ov;
        const double span = run.arcDeg + 2 * ov;
        const long n = static_cast<long>(std::floor(span / run.stepDeg + 1e-9));
        DirectedTrace p;
        p.direction = d;
        const auto sample = [&](double theta) {
            const AxisVector q = linearCircleCommands(m, run, theta);
            try {
                k.checkTravel(q);
            } catch (const ModelError& e) {
                throw ModelError(fmt::format("circle run '{}' at {:g}°: {}", run.name, theta, e.what()));
            }
            p.trace.angleDeg.push_back(theta);
            p.trace.dL.push_back((k.toolPointInWorkpiece(q, ball) - pivot).norm() - run.radius);
        };
        for (long i = 0; i <= n; ++i) sample(from + d * static_cast<double>(i) * run.stepDeg);
        const double to = from + d * span;
        if (std::abs(p.trace.angleDeg.back() - to) > 1e-9) sample(to);
        out.push_back(std::move(p));
    }
    return out;
}

}  // namespace cnccomp
