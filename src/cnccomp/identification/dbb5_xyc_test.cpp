#include "cnccomp/identification/dbb5_xyc_test.hpp"

#include <cmath>

#include <fmt/format.h>

#include "cnccomp/error.hpp"

namespace cnccomp::identification {
using namespace cnccomp::measurement;

namespace {

/// Ball position relative to the axis line, perpendicular part, bed frame.
Vec3 radial(const Kinematics& nominal, const Dbb5Run& run, int axis, const AxisVector& q) {
    const auto [p, w] = rotaryAxisLine(nominal, axis, q);
    const Vec3 v = nominal.baseToWorkpiece(q) * run.ball - p;
    return v - v.dot(w) * w;
}

}  // namespace

bool isDbb5XycTest(const MachineModel& m, const Dbb5Run& run) {
    if (run.kind != Dbb5Run::Kind::RotaryCircle) return false;
    const int axis = m.axisIndex(run.axis);
    if (axis < 0 || m.axisLink(axis).kind != AxisKind::Rotary) return false;
    const Kinematics nominal(m);
    const AxisVector q = dbb5SetupCommands(m, run);
    const Vec3 w = rotaryAxisLine(nominal, axis, q).second;
    return std::abs(run.barDirection.normalized().dot(w)) > 0.99 && radial(nominal, run, axis, q).norm() > 1.0;
}

Dbb5XycResult evaluateDbb5XycTest(const MachineModel& m, const Dbb5Run& run, const BallbarTrace& trace) {
    if (!isDbb5XycTest(m, run))
        throw ModelError(fmt::format("DBB5 run '{}' is not an XYC test (a rotary run with the bar along the turning axis "
                                     "and the ball off it)",
                                     run.name));
    if (trace.angleDeg.size() != trace.dL.size())
        throw ModelError(fmt::format("DBB5 run '{}': trace has {} angles and {} values", run.name, trace.angleDeg.size(),
                                     trace.dL.size()));
    const Kinematics nominal(m);
    const int axis = m.requireAxis(run.axis);
    Dbb5XycResult r;
    r.run = run.name;
    r.axis = run.axis;
    const Vec3 w0 = rotaryAxisLine(nominal, axis, dbb5SetupCommands(m, run)).second;
    w0.cwiseAbs().maxCoeff(&r.along);
    r.first = (r.along + 1) % 3;
    r.second = (r.along + 2) % 3;
    BallbarTrace azimuth;
    double radiusSum = 0;
    for (size_t i = 0; i < trace.angleDeg.size(); ++i) {
        const Vec3 v = radial(nominal, run, axis, dbb5Commands(m, run, trace.angleDeg[i]));
        azimuth.angleDeg.push_back(std::atan2(v[r.second], v[r.first]) / kDeg);
        radiusSum += v.norm();
    }
    azimuth.dL = trace.dL;
    r.radius = radiusSum / static_cast<double>(trace.angleDeg.size());
    r.iso = evaluateCircularTest(azimuth, r.radius);
    r.centre = r.iso.center;
    const double ua = run.barDirection.normalized()[r.along];
    r.rotation[r.second] = r.centre[0] / (r.radius * ua);
    r.rotation[r.first] = -r.centre[1] / (r.radius * ua);
    r.paper = paperXycTilt(r.centre[0], r.centre[1], r.radius);
    return r;
}

}  // namespace cnccomp::identification
