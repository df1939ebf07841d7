#include "cnccomp/identification/dbb5_run.hpp"

#include <cmath>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/identification/dbb5_cone_frustum.hpp"
#include "cnccomp/identification/rtest_run.hpp"

namespace cnccomp {

void Dbb5Run::validate() const {
    const auto bad = [&](const std::string& what) { throw ModelError(fmt::format("DBB5 run '{}': {}", name, what)); };
    for (double v : {LB, toolLength, startDeg, endDeg, stepDeg, setupDeg, coneTiltDeg, toolAngleDeg, barAngleDeg})
        if (!std::isfinite(v)) bad("geometry values must be finite numbers");
    if (!ball.allFinite()) bad("the ball position must be finite");
    if (!(LB > 0)) bad("bar length LB must be positive");
    if (stepDeg == 0) bad("angle step must not be zero");
    if ((endDeg - startDeg) / stepDeg < 0) bad("angle step points away from the end angle");
    if (std::abs((endDeg - startDeg) / stepDeg) > 1e7) bad("more than 10 million samples");
    for (const auto& [axisName, value] : hold)
        if (!std::isfinite(value)) bad(fmt::format("held position of {} must be finite", axisName));
    if (kind == Kind::LinearCircle) {
        if (plane != "XY" && plane != "YZ" && plane != "ZX" && plane != "YX" && plane != "ZY" && plane != "XZ")
            bad(fmt::format("plane '{}' is not XY, YZ or ZX", plane));
    } else if (kind == Kind::RotaryCircle) {
        if (!barDirection.allFinite() || barDirection.norm() < 1e-9) bad("bar direction must be a non-zero vector");
        if (axis.empty()) bad("a rotary circle needs the turning axis");
    } else {
        if (!(toolAngleDeg >= 0 && toolAngleDeg < 90)) bad("tool angle must be in [0, 90) deg");
        if (!(barAngleDeg > 0 && barAngleDeg < 180)) bad("bar angle must be in (0, 180) deg");
        if (!(std::abs(coneTiltDeg) < 90)) bad("cone tilt must be within ±90 deg");
    }
}

std::vector<double> Dbb5Run::anglesDeg() const {
    validate();
    const double span = endDeg - startDeg;
    long n = static_cast<long>(std::floor(span / stepDeg + 1e-9)) + 1;
    const double last = startDeg + (n - 1) * stepDeg;
    if (n > 1 && std::abs(span) >= 360.0 - 1e-9 && std::abs(std::remainder(last - startDeg, 360.0)) < 1e-9) --n;
    std::vector<double> a(static_cast<size_t>(n));
    for (long i = 0; i < n; ++i) a[static_cast<size_t>(i)] = startDeg + i * stepDeg;
    return a;
}

std::pair<Vec3, Vec3> Dbb5Run::planeAxes() const {
    const auto unit = [](char c) { return Vec3::Unit(c == 'X' ? 0 : c == 'Y' ? 1 : 2); };
    return {unit(plane[0]), unit(plane[1])};
}

namespace {

AxisVector heldPose(const MachineModel& m, const Dbb5Run& run) {
    AxisVector q = AxisVector::Zero(m.axisCount());
    for (const auto& [name, deg] : run.hold) {
        const int i = m.axisIndex(name);
        if (i < 0) throw ModelError(fmt::format("DBB5 run '{}': machine '{}' has no axis '{}'", run.name, m.name, name));
        if (m.axisLink(i).kind != AxisKind::Rotary)
            throw ModelError(fmt::format("DBB5 run '{}': held axis '{}' is not rotary", run.name, name));
        q[i] = deg * kDeg;
    }
    return q;
}

int turningAxis(const MachineModel& m, const Dbb5Run& run) {
    const int i = m.axisIndex(run.axis);
    if (i < 0) throw ModelError(fmt::format("DBB5 run '{}': machine '{}' has no axis '{}'", run.name, m.name, run.axis));
    if (m.axisLink(i).kind != AxisKind::Rotary)
        throw ModelError(fmt::format("DBB5 run '{}': axis '{}' is not rotary", run.name, run.axis));
    return i;
}

AxisVector commandsAt(const Kinematics& nominal, const Dbb5Run& run, double angleDeg) {
    const MachineModel& m = nominal.machine();
    AxisVector q = heldPose(m, run);
    const Vec3 spindle = nominal.toolPoint(run.toolLength);
    const double a = angleDeg * kDeg;
    Vec3 target;
    if (run.kind == Dbb5Run::Kind::LinearCircle) {
        const auto [e1, e2] = run.planeAxes();
        const Pose bMw = nominal.baseToWorkpiece(q);
        const Vec3 bed = bMw * run.ball + run.LB * (std::cos(a) * e1 + std::sin(a) * e2);
        target = bMw.inverse(Eigen::Isometry) * bed;
    } else if (run.kind == Dbb5Run::Kind::ConeFrustum) {
        q = dbb5TableOrientation(m, dbb5ConeToolAxis(run, angleDeg), dbb5ConeBranch(m, run), q);
        target = run.ball + run.LB * dbb5ConeBarDirection(run, angleDeg);
    } else {
        q[turningAxis(m, run)] = a;
        const Pose bMw = nominal.baseToWorkpiece(q);
        target = run.ball + bMw.linear().transpose() * (run.LB * run.barDirection.normalized());
    }
    return followPoint(nominal, q, spindle, target);
}

AxisVector setupAt(const Kinematics& nominal, const Dbb5Run& run) {
    const MachineModel& m = nominal.machine();
    AxisVector q = heldPose(m, run);
    if (run.kind == Dbb5Run::Kind::RotaryCircle) q[turningAxis(m, run)] = run.setupDeg * kDeg;
    if (run.kind == Dbb5Run::Kind::ConeFrustum)
        q = dbb5TableOrientation(m, dbb5ConeToolAxis(run, run.setupDeg), dbb5ConeBranch(m, run), q);
    return followPoint(nominal, q, nominal.toolPoint(run.toolLength), run.ball);
}

}  // namespace

AxisVector dbb5Commands(const MachineModel& m, const Dbb5Run& run, double angleDeg) {
    run.validate();
    return commandsAt(Kinematics(m), run, angleDeg);
}

AxisVector dbb5SetupCommands(const MachineModel& m, const Dbb5Run& run) {
    run.validate();
    return setupAt(Kinematics(m), run);
}

BallbarTrace simulateDbb5(const Kinematics& k, const Dbb5Run& run) {
    const std::vector<double> angles = run.anglesDeg();
    const Kinematics nominal(k.machine());
    const Vec3 spindle = k.toolPoint(run.toolLength);
    const AxisVector q0 = setupAt(nominal, run);
    try {
        k.checkTravel(q0);
    } catch (const ModelError& e) {
        throw ModelError(fmt::format("DBB5 run '{}' setup: {}", run.name, e.what()));
    }
    const Vec3 table = k.toolPointInWorkpiece(q0, spindle);  // the table ball is set on the spindle ball
    BallbarTrace t;
    t.angleDeg = angles;
    t.dL.resize(angles.size());
    for (size_t i = 0; i < angles.size(); ++i) {
        const AxisVector q = commandsAt(nominal, run, angles[i]);
        try {
            k.checkTravel(q);
        } catch (const ModelError& e) {
            throw ModelError(fmt::format("DBB5 run '{}' at {:g} deg: {}", run.name, angles[i], e.what()));
        }
        t.dL[i] = (k.toolPointInWorkpiece(q, spindle) - table).norm() - run.LB;
    }
    return t;
}

std::pair<Vec3, Vec3> rotaryAxisLine(const Kinematics& k, int axis, const AxisVector& q) {
    for (const JointFrame& f : k.jointFrames(q))
        if (f.axis == axis) return {f.point, f.direction.normalized()};
    throw ModelError(fmt::format("machine '{}': axis number {} has no joint frame", k.machine().name, axis));
}

}  // namespace cnccomp
