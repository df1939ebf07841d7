#include "cnccomp/identification/dbb5_run.hpp"

#include <cmath>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/identification/dbb5_cone_frustum.hpp"
#include "cnccomp/identification/rtest_run.hpp"

namespace cnccomp::identification {
using namespace cnccomp::measurement;

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

}  // namespace cnccomp::identification
