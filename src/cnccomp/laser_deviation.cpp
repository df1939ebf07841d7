#include "cnccomp/laser_deviation.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>
#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/geometry.hpp"
#include "cnccomp/kinematics.hpp"

namespace cnccomp {
namespace {

/// The laser's pose for a target: the axis at `command`, the others at 0 or mid-travel when 0 is outside theirs.
AxisVector laserPose(const MachineModel& m, int axis, double command) {
    AxisVector q = AxisVector::Zero(m.axisCount());
    for (int i = 0; i < m.axisCount(); ++i) {
        const Link& l = m.axisLink(i);
        if (q[i] < l.min || q[i] > l.max) q[i] = std::isfinite(l.min) && std::isfinite(l.max) ? 0.5 * (l.min + l.max)
                                                  : std::isfinite(l.min) ? l.min : l.max;
    }
    q[axis] = command;
    return q;
}

/// Laser reading (mm) of the set's errors at pose q: (actual − nominal tool point) · unit direction of the axis.
double reading(const Kinematics& nominal, const Kinematics& actual, const AxisVector& q, int axis) {
    AxisVector q2 = q;
    q2[axis] += 1.0;
    const Vec3 p = nominal.toolPointInWorkpiece(q, Vec3::Zero());
    const Vec3 u = (nominal.toolPointInWorkpiece(q2, Vec3::Zero()) - p).normalized();
    return (actual.toolPointInWorkpiece(q, Vec3::Zero()) - p).dot(u);
}

}  // namespace

PositioningComponent positioningComponent(const MachineModel& m, const std::string& axisName, double atCommand) {
    const int axis = m.axisIndex(axisName);
    if (axis < 0) throw ModelError(fmt::format("machine '{}' has no axis '{}' (the laser file's axis)", m.name, axisName));
    const Link& link = m.axisLink(axis);
    if (link.kind != AxisKind::Linear)
        throw ModelError(fmt::format("axis '{}' of machine '{}' is not linear: the laser positioning runs are of a linear axis",
                                     axisName, m.name));
    const std::string name = "E" + axisName + axisName;
    const int index = m.deviationIndex(name);
    if (index < 0)
        throw ModelError(fmt::format("machine '{}' has no component error '{}' (the positioning of {}): add "
                                     "<component name=\"{}\" link=\"{}\" component=\"...\" basis=\"table\" nodes=\"...\"/> to "
                                     "its <deviations>", m.name, name, axisName, name, link.name));
    const DeviationDef& d = m.deviations[static_cast<size_t>(index)];
    const Side side = m.axisSide(axis);
    if (d.kind != DeviationKind::Component || d.side != side || &m.chain(side).links[static_cast<size_t>(d.link)] != &link)
        throw ModelError(fmt::format("deviation '{}' of machine '{}' is not a component error of axis {}'s link", name,
                                     m.name, axisName));
    if (d.basis.type == ComponentBasis::Type::Fourier)
        throw ModelError(fmt::format("deviation '{}': a Fourier basis cannot hold a linear axis' positioning error", name));
    // A unit component (table: 1 µm at every node; polynomial: 1 µm per mm, small enough to stay linear) and its
    // reading at `atCommand` (a polynomial vanishes at 0: the caller picks a command away from it).
    const int n = d.size();
    DeviationSet unit(m);
    for (int k = 0; k < n; ++k)
        unit.values[d.offset + k] = d.basis.type == ComponentBasis::Type::Table || k == 0 ? kUm : 0.0;
    const double e = d.basis.evaluate(atCommand, unit.values.data() + d.offset, link.modulo);
    if (std::abs(e) < 1e-12)
        throw ModelError(fmt::format("deviation '{}': the laser's targets are all at the axis' zero", name));
    const double s = reading(Kinematics(m), Kinematics(m, unit), laserPose(m, axis, atCommand), axis) / e;
    if (!(std::abs(s) > 0.5))
        throw ModelError(fmt::format("deviation '{}' of machine '{}' does not move the tool along axis {} (reading {:.3g} "
                                     "per unit): it is not that axis' positioning error", name, m.name, axisName, s));
    return {index, s};
}

LaserComponentResult setPositioningComponent(DeviationSet& set, const LaserPositioningResult& laser,
                                             const std::string& laserSource) {
    const MachineModel& m = set.machine();
    const int axis = m.axisIndex(laser.axis);
    if (axis < 0) throw ModelError(fmt::format("machine '{}' has no axis '{}' (the laser file's axis)", m.name, laser.axis));
    const Link& link = m.axisLink(axis);
    std::vector<double> q, x;  // commands (mm) and mean bidirectional deviations (mm) at the targets
    for (const LaserTargetResult& t : laser.targets) {
        AxisVector c = AxisVector::Zero(m.axisCount());
        c[axis] = t.target;
        const double command = m.fromController(c)[axis];
        if (command < link.min - 1e-9 || command > link.max + 1e-9)
            throw InputError(laserSource, 0, fmt::format("target {:g} mm is outside the travel of {} ({:g} .. {:g} mm "
                                                         "in machine coordinates)", t.target, laser.axis,
                                                         link.min - link.machineZero, link.max - link.machineZero));
        q.push_back(command);
        x.push_back(t.mean * kUm);
    }

    // Sensitivity at the target farthest from 0.
    const size_t far = static_cast<size_t>(std::max_element(q.begin(), q.end(), [](double a, double b) {
                                                return std::abs(a) < std::abs(b);
                                            }) - q.begin());
    const PositioningComponent pc = positioningComponent(m, laser.axis, q[far]);
    const int index = pc.deviation;
    const DeviationDef& d = m.deviations[static_cast<size_t>(index)];
    const int n = d.size();
    const double s = pc.sensitivity;
    const std::string name = d.name;

    LaserComponentResult r;
    r.component = name;
    r.sensitivity = s;
    r.meanReversalUm = laser.meanReversal;
    r.reversalUm = laser.B;
    Eigen::Map<Eigen::VectorXd> coef(set.values.data() + d.offset, n);
    if (d.basis.type == ComponentBasis::Type::Table) {
        for (int k = 0; k < n; ++k) {
            const double node = d.basis.nodes[static_cast<size_t>(k)];
            AxisVector c = AxisVector::Zero(m.axisCount());
            c[axis] = node;
            const double P = m.toController(c)[axis];
            if (P < laser.targets.front().target - 1e-9 || P > laser.targets.back().target + 1e-9) ++r.nodesOutside;
            coef[k] = 0.5 * (laser.errorAt(P, true) + laser.errorAt(P, false)) * kUm / s;
        }
    } else {
        Eigen::MatrixXd A(static_cast<Eigen::Index>(q.size()), n);
        Eigen::VectorXd b(static_cast<Eigen::Index>(q.size()));
        for (size_t i = 0; i < q.size(); ++i) {
            double p = q[i];
            for (int k = 0; k < n; ++k, p *= q[i]) A(static_cast<Eigen::Index>(i), k) = p;
            b[static_cast<Eigen::Index>(i)] = x[i] / s;
        }
        coef = A.colPivHouseholderQr().solve(b);
    }
    for (size_t i = 0; i < q.size(); ++i)
        r.largestResidualUm = std::max(r.largestResidualUm,
                                       std::abs(x[i] - s * d.basis.evaluate(q[i], coef.data(), link.modulo)) / kUm);
    set.present[static_cast<size_t>(index)] = 1;
    set.setReversal(laser.axis, laser.meanReversal * kUm);
    return r;
}

DeviationSet mergeDeviations(const DeviationSet& base, const DeviationSet& update) {
    if (&base.machine() != &update.machine())
        throw ModelError("mergeDeviations: the two deviation sets belong to different machine descriptions");
    const MachineModel& m = base.machine();
    DeviationSet out = base;
    for (size_t i = 0; i < m.deviations.size(); ++i) {
        if (!update.present[i]) continue;
        const DeviationDef& d = m.deviations[i];
        if (d.kind == DeviationKind::Location) {
            out.setIsoValue(static_cast<int>(i), update.isoValue(static_cast<int>(i)));
        } else {
            out.values.segment(d.offset, d.size()) = update.values.segment(d.offset, d.size());
            out.present[i] = 1;
        }
    }
    for (size_t a = 0; a < update.reversalPresent.size(); ++a)
        if (update.reversalPresent[a]) {
            out.reversal[a] = update.reversal[a];
            out.reversalPresent[a] = 1;
        }
    return out;
}

std::vector<std::string> reversalMergeLines(const DeviationSet& base, const DeviationSet& update, const std::string& updateName) {
    const MachineModel& m = base.machine();
    std::vector<std::string> out;
    for (size_t a = 0; a < base.reversalPresent.size() && a < update.reversalPresent.size(); ++a) {
        const std::string name = "B" + m.axisNames[a];
        if (update.reversalPresent[a])
            out.push_back(base.reversalPresent[a]
                              ? fmt::format("{} = {:.4f} um from {} (replaces the base's {:.4f} um)", name, update.reversal[a] / kUm,
                                            updateName, base.reversal[a] / kUm)
                              : fmt::format("{} = {:.4f} um from {} (the base had none)", name, update.reversal[a] / kUm, updateName));
        else if (base.reversalPresent[a])
            out.push_back(fmt::format("{} = {:.4f} um kept from the base ({} did not determine it)", name, base.reversal[a] / kUm,
                                      updateName));
    }
    return out;
}

}  // namespace cnccomp
