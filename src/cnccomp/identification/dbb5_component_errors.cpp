#include "cnccomp/identification/dbb5_component_errors.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/identification/dbb5_observation.hpp"

namespace cnccomp::identification {
using namespace cnccomp::measurement;

namespace {

constexpr const char* kXyz = "XYZ";

struct Used {
    int run = -1;
    double s = 0;  ///< ball position along the axis
};

bool othersAtZero(const Dbb5Run& r) {
    for (const auto& [a, v] : r.hold)
        if (std::abs(v) > 1e-9) return false;
    return true;
}

/// Measured minus simulated-with-the-location-errors ΔL, at the trace's angles.
Eigen::VectorXd residual(const MachineModel& m, const Kinematics& location, const Dbb5Run& run, const BallbarTrace& t) {
    const Dbb5Observation obs(m, run, t);
    Eigen::VectorXd predicted(obs.size());
    obs.predict(location, nullptr, predicted.data());
    return obs.measured() - predicted;
}

/// Profile value (translation, tilt) at angle `deg` by linear interpolation, wrapping over a full turn.
std::pair<Vec3, Vec3> interpolate(const Dbb5ComponentProfile& p, double deg, bool modulo) {
    std::vector<size_t> order(p.angleDeg.size());
    std::iota(order.begin(), order.end(), size_t{0});
    std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return p.angleDeg[a] < p.angleDeg[b]; });
    const double lo = p.angleDeg[order.front()], hi = p.angleDeg[order.back()];
    double gap = 0;
    for (size_t i = 1; i < order.size(); ++i) gap = std::max(gap, p.angleDeg[order[i]] - p.angleDeg[order[i - 1]]);
    const bool wraps = modulo && 360.0 - (hi - lo) <= gap * (1 + 1e-9) + 1e-9;
    double a = deg;
    if (wraps) {
        a = std::fmod(deg - lo, 360.0);
        if (a < 0) a += 360.0;
        a += lo;
    }
    if (a < lo - 1e-9 || (!wraps && a > hi + 1e-9))
        throw ModelError(fmt::format("axis {}: table node {:g} deg is outside the measured angles [{:g}, {:g}]", p.axis,
                                     deg, lo, hi));
    const auto at = [&](size_t i) { return std::pair<Vec3, Vec3>{p.translation[i], p.tilt[i]}; };
    for (size_t i = 0; i + 1 < order.size(); ++i) {
        const double a0 = p.angleDeg[order[i]], a1 = p.angleDeg[order[i + 1]];
        if (a >= a0 - 1e-9 && a <= a1 + 1e-9) {
            const double f = a1 > a0 ? std::clamp((a - a0) / (a1 - a0), 0.0, 1.0) : 0.0;
            return {(1 - f) * p.translation[order[i]] + f * p.translation[order[i + 1]],
                    (1 - f) * p.tilt[order[i]] + f * p.tilt[order[i + 1]]};
        }
    }
    if (a <= lo + 1e-9) return at(order.front());
    // Between the last angle and the first one a turn later.
    const double f = (a - hi) / (lo + 360.0 - hi);
    return {(1 - f) * p.translation[order.back()] + f * p.translation[order.front()],
            (1 - f) * p.tilt[order.back()] + f * p.tilt[order.front()]};
}

}  // namespace

Dbb5ComponentProfile dbb5ComponentProfile(const MachineModel& m, const std::vector<Dbb5Run>& runs,
                                          const std::vector<BallbarTrace>& traces, const DeviationSet& location,
                                          const std::string& axis) {
    if (runs.size() != traces.size()) throw ModelError(fmt::format("{} DBB5 runs but {} traces", runs.size(), traces.size()));
    const int ai = m.requireAxis(axis);
    if (m.axisLink(ai).kind != AxisKind::Rotary) throw ModelError(fmt::format("axis {} is not rotary", axis));
    const Kinematics nominal(m), withLocation(m, location);
    Dbb5ComponentProfile p;
    p.axis = axis;
    m.nominalDirection(ai).cwiseAbs().maxCoeff(&p.along);
    p.first = (p.along + 1) % 3;
    p.second = (p.along + 2) % 3;
    std::vector<Used> by[3];
    for (size_t i = 0; i < runs.size(); ++i) {
        const Dbb5Run& r = runs[i];
        if (r.kind != Dbb5Run::Kind::RotaryCircle || r.axis != axis || !othersAtZero(r)) continue;
        const Vec3 u = r.barDirection.normalized();
        int kb = 0;
        u.cwiseAbs().maxCoeff(&kb);
        if (std::abs(u[kb]) < 0.99) continue;
        const AxisVector q0 = dbb5SetupCommands(m, r);
        const auto [point, dir] = rotaryAxisLine(nominal, ai, q0);
        const Vec3 v = nominal.baseToWorkpiece(q0) * r.ball - point;
        if ((v - v.dot(dir) * dir).norm() > 0.01) continue;  // the ball must sit on the axis
        by[kb].push_back({static_cast<int>(i), (nominal.baseToWorkpiece(q0) * r.ball)[p.along]});
    }
    for (int k : {p.first, p.second})
        if (by[k].empty())
            throw ModelError(fmt::format("DBB5 component errors of {} need a run turning {} with the ball on its axis and "
                                         "the bar along {} (the other rotary axes at 0)",
                                         axis, axis, kXyz[k]));
    const auto lowHigh = [](const std::vector<Used>& v) {
        const auto [lo, hi] = std::minmax_element(v.begin(), v.end(), [](const Used& a, const Used& b) { return a.s < b.s; });
        return std::pair<Used, Used>{*lo, *hi};
    };
    const auto [f1, f2] = lowHigh(by[p.first]);
    const auto [s1, s2] = lowHigh(by[p.second]);
    p.tilts = f2.s - f1.s > 1e-6 && s2.s - s1.s > 1e-6;
    p.axial = !by[p.along].empty();
    p.reference = p.tilts ? rotaryAxisLine(nominal, ai, AxisVector::Zero(m.axisCount())).first[p.along] : f1.s;

    std::vector<Used> used = {f1, s1};
    if (p.tilts) used.insert(used.end(), {f2, s2});
    if (p.axial) used.push_back(lowHigh(by[p.along]).first);
    const BallbarTrace& ref = traces[static_cast<size_t>(f1.run)];
    std::vector<Eigen::VectorXd> along;  // displacement along each used run's bar axis
    for (const Used& u : used) {
        const Dbb5Run& r = runs[static_cast<size_t>(u.run)];
        const BallbarTrace& t = traces[static_cast<size_t>(u.run)];
        bool same = t.angleDeg.size() == ref.angleDeg.size();
        for (size_t i = 0; same && i < t.angleDeg.size(); ++i) same = std::abs(t.angleDeg[i] - ref.angleDeg[i]) < 1e-9;
        if (!same)
            throw ModelError(fmt::format("DBB5 component errors of {}: run '{}' has other sample angles than '{}'", axis,
                                         r.name, runs[static_cast<size_t>(f1.run)].name));
        const Vec3 dir = r.barDirection.normalized();
        int kb = 0;
        dir.cwiseAbs().maxCoeff(&kb);
        along.push_back(-residual(m, withLocation, r, t) / dir[kb]);
        p.runs.push_back(r.name);
    }
    const size_t n = ref.angleDeg.size();
    p.angleDeg = ref.angleDeg;
    p.translation.assign(n, Vec3::Zero());
    p.tilt.assign(n, Vec3::Zero());
    for (size_t i = 0; i < n; ++i) {
        const auto k = static_cast<Eigen::Index>(i);
        Vec3& d = p.translation[i];
        Vec3& e = p.tilt[i];
        if (p.tilts) {
            e[p.second] = (along[2][k] - along[0][k]) / (f2.s - f1.s);
            e[p.first] = -(along[3][k] - along[1][k]) / (s2.s - s1.s);
        }
        d[p.first] = along[0][k] - (f1.s - p.reference) * e[p.second];
        d[p.second] = along[1][k] + (s1.s - p.reference) * e[p.first];
        if (p.axial) d[p.along] = along.back()[k];
    }
    return p;
}

DeviationSet dbb5ComponentTables(const MachineModel& m, const Dbb5ComponentProfile& p, const DeviationSet& base) {
    if (p.angleDeg.empty()) throw ModelError(fmt::format("axis {}: the component profile is empty", p.axis));
    DeviationSet set = base;
    const int ai = m.requireAxis(p.axis);
    const Side side = m.axisSide(ai);
    const auto& links = m.chain(side).links;
    Mat3 before = Mat3::Identity();  // nominal rotation up to the axis' own motion (the axes before it at 0)
    int li = -1;
    for (size_t i = 0; i < links.size() && li < 0; ++i) {
        before = before * links[i].placement.linear();
        if (links[i].axisIndex == ai) li = static_cast<int>(i);
    }
    const Link& link = links[static_cast<size_t>(li)];
    const Vec3 dir = link.direction.normalized();
    for (size_t di = 0; di < m.deviations.size(); ++di) {
        const DeviationDef& d = m.deviations[di];
        if (d.side != side || d.link != li || d.kind != DeviationKind::Component) continue;
        if (d.basis.type != ComponentBasis::Type::Table)
            throw ModelError(fmt::format("machine '{}': component error {} of {} is not a table over angle", m.name,
                                         d.name, p.axis));
        const bool rotation = d.component >= 3;
        const bool aboutAxis = std::abs(Vec3::Unit(d.component % 3).dot(dir)) > 0.99;
        if (rotation ? (aboutAxis || !p.tilts) : (aboutAxis && !p.axial)) continue;
        for (size_t k = 0; k < d.basis.nodes.size(); ++k) {
            const double node = d.basis.nodes[k];
            const auto [t, e] = interpolate(p, node / kDeg, link.modulo);
            const Mat3 R = before * axisRotation(dir, node);
            set.values[d.offset + static_cast<int>(k)] = (R.transpose() * (rotation ? e : t))[d.component % 3];
        }
        set.present[di] = 1;
    }
    return set;
}

}  // namespace cnccomp::identification
