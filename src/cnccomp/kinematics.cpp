#include "cnccomp/kinematics.hpp"

#include <cmath>

#include <fmt/format.h>

#include "cnccomp/error.hpp"

namespace cnccomp {

Kinematics::Kinematics(const MachineModel& machine) : machine_(&machine) { build(nullptr); }

Kinematics::Kinematics(const MachineModel& machine, const DeviationSet& deviations) : machine_(&machine) {
    deviations.requireMachine(machine);
    build(&deviations);
}

void Kinematics::build(const DeviationSet* deviations) {
    values_ = deviations ? deviations->values : Eigen::VectorXd::Zero(machine_->parameterCount());
    for (Side side : {Side::Workpiece, Side::Tool}) {
        const Chain& chain = machine_->chain(side);
        auto& out = side == Side::Tool ? tool_ : workpiece_;
        out.clear();
        for (int i = 0; i < static_cast<int>(chain.links.size()); ++i) {
            const Link& l = chain.links[i];
            Vec6 location = Vec6::Zero();
            LinkData d{Pose::Identity(), l.direction, l.kind, l.axisIndex, l.modulo, {}};
            for (int k = 0; k < static_cast<int>(machine_->deviations.size()); ++k) {
                const DeviationDef& def = machine_->deviations[k];
                if (def.side != side || def.link != i) continue;
                if (def.kind == DeviationKind::Location)
                    location[def.component] += values_[def.offset];
                else
                    d.components.push_back(k);
            }
            d.placed = l.placement * errorTransform(location);
            out.push_back(std::move(d));
        }
    }
}

Pose Kinematics::chainPose(const std::vector<LinkData>& links, const AxisVector& q, Side side,
                           JointFrames* joints) const {
    Pose m = Pose::Identity();
    for (const LinkData& l : links) {
        m = m * l.placed;
        if (joints && l.kind != AxisKind::Fixed)
            joints->items[joints->count++] = {side, l.axis, l.kind == AxisKind::Rotary, m.linear() * l.direction,
                                              m.translation()};
        if (l.kind == AxisKind::Linear) {
            m.translation() += m.linear() * (l.direction * q[l.axis]);
        } else if (l.kind == AxisKind::Rotary) {
            m.linear() = m.linear() * axisRotation(l.direction, q[l.axis]);
        }
        if (!l.components.empty()) {
            Vec6 e = Vec6::Zero();
            for (int k : l.components) {
                const DeviationDef& def = machine_->deviations[k];
                e[def.component] += def.basis.evaluate(q[l.axis], values_.data() + def.offset, l.modulo);
            }
            m = m * errorTransform(e);
        }
    }
    return m;
}

JointFrames Kinematics::jointFrames(const AxisVector& q) const {
    JointFrames j;
    chainPose(workpiece_, q, Side::Workpiece, &j);
    chainPose(tool_, q, Side::Tool, &j);
    return j;
}

Pose Kinematics::baseToWorkpiece(const AxisVector& q) const { return chainPose(workpiece_, q); }
Pose Kinematics::baseToTool(const AxisVector& q) const { return chainPose(tool_, q); }

Pose Kinematics::workpieceToTool(const AxisVector& q) const {
    return baseToWorkpiece(q).inverse(Eigen::Isometry) * baseToTool(q);
}

Vec3 Kinematics::toolPointInWorkpiece(const AxisVector& q, const Vec3& p) const {
    return baseToWorkpiece(q).inverse(Eigen::Isometry) * (baseToTool(q) * p);
}

void Kinematics::checkTravel(const AxisVector& q) const {
    if (q.size() != machine_->axisCount())
        throw ModelError(fmt::format("machine '{}' has {} axes, got {} commands", machine_->name,
                                     machine_->axisCount(), q.size()));
    for (int i = 0; i < q.size(); ++i) {
        const Link& l = machine_->axisLink(i);
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
