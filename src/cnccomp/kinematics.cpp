#include "cnccomp/kinematics.hpp"

#include <cmath>

#include <fmt/format.h>

#include "cnccomp/error.hpp"

namespace cnccomp {

namespace {

Pose asPose(const Frame& f) {
    Pose p = Pose::Identity();
    p.linear() = f.R;
    p.translation() = f.t;
    return p;
}

}  // namespace

Kinematics::Kinematics(const MachineModel& machine)
    : model_(machine, nullptr, KinematicsModel::Arithmetic::AsExactModel) {}

Kinematics::Kinematics(const MachineModel& machine, const DeviationSet& deviations)
    : model_(machine, &deviations, KinematicsModel::Arithmetic::AsExactModel) {}

JointFrames Kinematics::jointFrames(const AxisVector& q) const {
    JointFrames j;
    model_.chainFrame(Side::Workpiece, q, &j);
    model_.chainFrame(Side::Tool, q, &j);
    return j;
}

Pose Kinematics::baseToWorkpiece(const AxisVector& q) const { return asPose(model_.chainFrame(Side::Workpiece, q)); }
Pose Kinematics::baseToTool(const AxisVector& q) const { return asPose(model_.chainFrame(Side::Tool, q)); }

Pose Kinematics::workpieceToTool(const AxisVector& q) const {
    return baseToWorkpiece(q).inverse(Eigen::Isometry) * baseToTool(q);
}

Vec3 Kinematics::toolPointInWorkpiece(const AxisVector& q, const Vec3& p) const {
    return baseToWorkpiece(q).inverse(Eigen::Isometry) * (baseToTool(q) * p);
}

void Kinematics::checkTravel(const AxisVector& q) const {
    if (q.size() != machine().axisCount())
        throw ModelError(fmt::format("machine '{}' has {} axes, got {} commands", machine().name,
                                     machine().axisCount(), q.size()));
    for (int i = 0; i < q.size(); ++i) {
        const Link& l = machine().axisLink(i);
        const double scale = l.kind == AxisKind::Rotary ? 1.0 / kDeg : 1.0;
        const char* unit = l.kind == AxisKind::Rotary ? "deg" : "mm";
        if (!std::isfinite(q[i]))
            throw ModelError(fmt::format("axis {} command is not a finite number", l.name));
        if (q[i] < l.min - 1e-9 || q[i] > l.max + 1e-9)
            throw ModelError(fmt::format("axis {} command {:.4f} {} is outside its travel [{:g}, {:g}] {}", l.name,
                                         q[i] * scale, unit, l.min * scale, l.max * scale, unit));
    }
}

}  // namespace cnccomp
