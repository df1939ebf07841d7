#include "cnccomp/identification/axis_line.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "cnccomp/error.hpp"

namespace cnccomp::identification {

void setAxisLine(const MachineModel& m, DeviationSet& set, int axis, const AxisVector& q, const Vec3& pointBed,
                 const Vec3& dirBed, const std::vector<int>& only) {
    const Side side = m.axisSide(axis);
    const Chain& chain = m.chain(side);
    Pose frame = Pose::Identity();
    int linkIndex = -1;
    for (int i = 0; i < static_cast<int>(chain.links.size()); ++i) {
        const Link& l = chain.links[static_cast<size_t>(i)];
        frame = frame * l.placement;
        if (l.axisIndex == axis) {
            linkIndex = i;
            break;
        }
        if (l.kind == AxisKind::Linear) frame.translation() += frame.linear() * (l.direction * q[l.axisIndex]);
        if (l.kind == AxisKind::Rotary) frame.linear() = frame.linear() * axisRotation(l.direction, q[l.axisIndex]);
    }
    const Link& link = chain.links[static_cast<size_t>(linkIndex)];
    if (link.kind != AxisKind::Rotary) throw ModelError(fmt::format("axis {} is not rotary", link.name));
    const Vec3 u = link.direction.normalized();
    const Vec3 p = frame.inverse(Eigen::Isometry) * pointBed;
    Vec3 n = (frame.linear().transpose() * dirBed).normalized();
    if (n.dot(u) < 0) n = -n;
    if (!(n.dot(u) > 0.5)) throw ModelError(fmt::format("axis {}: the measured direction is far from the nominal one", link.name));
    const Vec3 t = p - (p.dot(u) / n.dot(u)) * n;
    const Vec3 c = u.cross(n);
    const Vec3 w = c.norm() > 0 ? Vec3(std::atan2(c.norm(), u.dot(n)) * c / c.norm()) : Vec3::Zero();
    for (int di : only) {
        const DeviationDef& d = m.deviations[static_cast<size_t>(di)];
        if (d.side != side || d.link != linkIndex || d.kind != DeviationKind::Location) continue;
        set.values[d.offset] = d.component < 3 ? t[d.component] : w[d.component - 3];
        set.present[static_cast<size_t>(di)] = 1;
    }
}

}  // namespace cnccomp::identification
