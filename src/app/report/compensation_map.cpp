#include "app/report/compensation_map.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "cnccomp/map_grid.hpp"
#include "controllers/common/evaluate.hpp"

namespace cnccomp::app::report {

bool singularPose(const Kinematics& k, const AxisVector& q) {
    const Vec3 axis = k.baseToTool(q).linear() * k.machine().toolDirection;
    for (const JointFrame& j : k.jointFrames(q))
        if (j.rotary && j.direction.cross(axis).norm() < 0.1) return true;
    return false;
}

std::string defaultMapGrid(const MachineModel& m) {
    const Kinematics k(m);
    AxisVector q = AxisVector::Zero(m.axisCount());
    for (int a = 0; a < m.axisCount(); ++a) q[a] = std::clamp(0.0, m.axisLink(a).min, m.axisLink(a).max);
    for (int a = 0; a < m.axisCount() && singularPose(k, q); ++a) {
        const Link& l = m.axisLink(a);
        if (l.kind != AxisKind::Rotary) continue;
        for (double deg : {30.0, 45.0, -30.0, 60.0}) {
            AxisVector t = q;
            t[a] = deg * kDeg;
            if (t[a] < l.min || t[a] > l.max || singularPose(k, t)) continue;
            q = t;
            break;
        }
    }
    std::string g;
    for (int a = 0; a < m.axisCount(); ++a) {
        const Link& l = m.axisLink(a);
        const std::string& n = m.axisNames[a];
        if ((n == "X" || n == "Y") && l.kind == AxisKind::Linear) {
            const double lo = std::max(l.min, -200.0), hi = std::min(l.max, 200.0);
            if (hi - lo > 1e-6) {
                g += fmt::format("{}{}={:g}:{:g}:{:g}", g.empty() ? "" : " ", n, lo, hi, (hi - lo) / 20);
                continue;
            }
        }
        g += fmt::format("{}{}={:g}", g.empty() ? "" : " ", n, q[a] / (l.kind == AxisKind::Rotary ? kDeg : 1.0));
    }
    return g;
}

VolumetricMap uncompensatedMap(const MachineModel& m, const DeviationSet& deviations, const MapOptions& o) {
    MapRequest req{m, deviations, parseGrid(o.grid.empty() ? defaultMapGrid(m) : o.grid, "report map grid"), o.toolLength, {}, 0};
    return computeMap(req);
}

std::vector<AxisVector> regularWorkspaceSamples(const MachineModel& m, int perAxis) {
    std::vector<AxisVector> samples;
    const Kinematics nominal(m);
    for (const AxisVector& q : controllers::common::workspaceSamples(m, perAxis))
        if (!singularPose(nominal, q)) samples.push_back(q);
    return samples;
}

VolumetricMap compensatedMap(const VolumetricMap& before, const MachineModel& m, const DeviationSet& deviations,
                             const controllers::AppliedCompensation& comp, double toolLength) {
    VolumetricMap map = before;
    const Kinematics actual(m, deviations), nominal(m);
    const Vec3 tipActual = actual.toolPoint(toolLength), tipNominal = nominal.toolPoint(toolLength);
    double sum = 0;
    map.stats.norm = {};
    long n = 0;
    AxisVector q(m.axisCount());
    for (MapPoint& p : map.points) {
        if (!p.ok) continue;
        for (int a = 0; a < m.axisCount(); ++a) q[a] = p.q[static_cast<size_t>(a)];
        const AxisVector drive = comp.driveCommandsForTool(q, toolLength);
        p.error = actual.toolPointInWorkpiece(drive, tipActual) - nominal.toolPointInWorkpiece(q, tipNominal);
        p.rotation.setZero();
        p.tilt = 0;
        map.stats.norm.maxAbs = std::max(map.stats.norm.maxAbs, p.error.norm());
        sum += p.error.squaredNorm();
        ++n;
    }
    map.stats.norm.rms = n > 0 ? std::sqrt(sum / static_cast<double>(n)) : 0.0;
    return map;
}

}  // namespace cnccomp::app::report
