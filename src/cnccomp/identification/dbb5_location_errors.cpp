#include "cnccomp/identification/dbb5_location_errors.hpp"

#include <cmath>
#include <memory>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/identification/dbb5_observation.hpp"
#include "cnccomp/identification/reading_refinement.hpp"
#include "cnccomp/kinematics.hpp"

namespace cnccomp::identification {
using namespace cnccomp::measurement;

namespace {

constexpr const char* kLinearAxes = "XYZ";

double held(const Dbb5Run& r, const std::string& axis) {
    for (const auto& [a, v] : r.hold)
        if (a == axis) return v;
    return 0.0;
}

int alongIndex(const MachineModel& m, const std::string& axis) {
    int k = 0;
    m.nominalDirection(m.requireAxis(axis)).cwiseAbs().maxCoeff(&k);
    return k;
}

/// Two runs of one role, at the lowest and highest position along the turning axis.
struct Pair {
    int lo = -1, hi = -1;
    double sLo = 0, sHi = 0;
    void consider(int run, double s) {
        if (lo < 0 || s < sLo) lo = run, sLo = s;
        if (hi < 0 || s > sHi) hi = run, sHi = s;
    }
};

struct AxisRoles {
    std::string axis, other;
    int along = 2, first = 0, second = 1;
    Pair pairFirst, pairSecond;  ///< bar along `first` / `second`
};

struct Roles {
    int xy = -1, yz = -1, zx = -1;
    AxisRoles outer, inner;
};

AxisRoles axisRoles(const MachineModel& m, const std::string& axis, const std::string& other) {
    AxisRoles a;
    a.axis = axis;
    a.other = other;
    a.along = alongIndex(m, axis);
    a.first = (a.along + 1) % 3;
    a.second = (a.along + 2) % 3;
    return a;
}

Roles findRoles(const MachineModel& m, const std::vector<Dbb5Run>& runs, const std::string& outer,
                const std::string& inner) {
    Roles r;
    r.outer = axisRoles(m, outer, inner);
    r.inner = axisRoles(m, inner, outer);
    const Kinematics nominal(m);
    for (size_t i = 0; i < runs.size(); ++i) {
        const Dbb5Run& run = runs[i];
        const int idx = static_cast<int>(i);
        if (run.kind == Dbb5Run::Kind::LinearCircle) {
            if (run.plane == "XY" && r.xy < 0) r.xy = idx;
            if (run.plane == "YZ" && r.yz < 0) r.yz = idx;
            if (run.plane == "ZX" && r.zx < 0) r.zx = idx;
            continue;
        }
        if (run.kind != Dbb5Run::Kind::RotaryCircle) continue;
        AxisRoles* a = run.axis == outer ? &r.outer : run.axis == inner ? &r.inner : nullptr;
        if (!a || std::abs(held(run, a->other)) > 1e-9) continue;
        int kb = 0;
        run.barDirection.cwiseAbs().maxCoeff(&kb);
        if (kb == a->along) continue;  // axial runs (XYC test, axial error motion) do not see the line
        const Vec3 ballBed = nominal.baseToWorkpiece(dbb5SetupCommands(m, run)) * run.ball;
        (kb == a->first ? a->pairFirst : a->pairSecond).consider(idx, ballBed[a->along]);
    }
    if (r.xy < 0 || r.yz < 0 || r.zx < 0)
        throw ModelError("DBB5 location errors need a linear circle in each plane XY, YZ and ZX");
    for (const AxisRoles* a : {&r.outer, &r.inner})
        for (const auto& [k, p] : {std::pair<int, const Pair*>{a->first, &a->pairFirst}, {a->second, &a->pairSecond}})
            if (p->lo < 0 || !(p->sHi - p->sLo > 1e-6))
                throw ModelError(fmt::format("DBB5 location errors need two {} runs with the bar along {} at different "
                                             "{} positions ({} at 0)",
                                             a->axis, kLinearAxes[k], kLinearAxes[a->along], a->other));
    return r;
}

struct Readings {
    Dbb5Squareness squareness;
    Dbb5AxisLine outer, inner;
};

Eigen::VectorXd pack(const Dbb5Squareness& s, const Dbb5AxisLine& outer, const Dbb5AxisLine& inner) {
    Eigen::VectorXd v(11);
    v << s.xy, s.yz, s.zx, outer.position[outer.first], outer.position[outer.second], outer.rotation[outer.first],
        outer.rotation[outer.second], inner.position[inner.first], inner.position[inner.second],
        inner.rotation[inner.first], inner.rotation[inner.second];
    return v;
}

/// The plain formulas on one data set (only the runs with a role are evaluated).
Readings readings(const std::vector<Dbb5Run>& runs, const std::vector<const BallbarTrace*>& traces, const Roles& r) {
    const auto iso = [&](int i) {
        return evaluateCircularTest(*traces[static_cast<size_t>(i)], runs[static_cast<size_t>(i)].LB);
    };
    Readings out;
    Dbb5Squareness& s = out.squareness;
    s.b2XY = iso(r.xy).b2;
    s.b2YZ = iso(r.yz).b2;
    s.b2ZX = iso(r.zx).b2;
    s.xy = 2 * s.b2XY / runs[static_cast<size_t>(r.xy)].LB;
    s.yz = 2 * s.b2YZ / runs[static_cast<size_t>(r.yz)].LB;
    s.zx = 2 * s.b2ZX / runs[static_cast<size_t>(r.zx)].LB;
    const auto shifts = [&](const Pair& p, int e) {
        const Dbb5Run &lo = runs[static_cast<size_t>(p.lo)], &hi = runs[static_cast<size_t>(p.hi)];
        return Dbb5ShiftPair{lo.name, hi.name, p.sLo, p.sHi, dbb5CentreShift(iso(p.lo).meanRadialError, lo.barDirection, e),
                             dbb5CentreShift(iso(p.hi).meanRadialError, hi.barDirection, e)};
    };
    const auto line = [&](const AxisRoles& a) {
        return axisLineFromShifts(a.axis, a.along, shifts(a.pairFirst, a.first), shifts(a.pairSecond, a.second));
    };
    out.outer = line(r.outer);
    out.inner = line(r.inner);
    return out;
}

/// The model's location deviations of an axis in reading order (position first, second; rotation first, second),
/// found by link and component (whatever their names).
std::vector<int> axisDeviations(const MachineModel& m, const AxisRoles& a) {
    const int axis = m.requireAxis(a.axis);
    const Side side = m.axisSide(axis);
    const auto& links = m.chain(side).links;
    int link = -1;
    for (size_t i = 0; i < links.size(); ++i)
        if (links[i].axisIndex == axis) link = static_cast<int>(i);
    std::vector<int> out;
    const int components[4] = {a.first, a.second, 3 + a.first, 3 + a.second};
    for (const int c : components) {
        const char letter = c < 3 ? "XYZ"[c] : "ABC"[c - 3];
        int found = -1;
        for (size_t i = 0; i < m.deviations.size(); ++i) {
            const DeviationDef& d = m.deviations[i];
            if (d.side == side && d.link == link && d.kind == DeviationKind::Location && d.component == c)
                found = static_cast<int>(i);
        }
        if (found < 0)
            throw ModelError(fmt::format("machine '{}' has no location deviation E{}0{} of axis {} (the DBB5 formulas "
                                         "identify it)",
                                         m.name, letter, a.axis, a.axis));
        out.push_back(found);
    }
    return out;
}

std::vector<int> modelDeviations(const MachineModel& m, const std::string& outer, const std::string& inner) {
    std::vector<int> devs;
    for (const char* n : {"EC0Y", "EA0Z", "EB0Z"}) {
        const int i = m.deviationIndex(n);
        if (i < 0) throw ModelError(fmt::format("machine '{}' has no deviation '{}' (the DBB5 formulas identify it)", m.name, n));
        devs.push_back(i);
    }
    for (const AxisRoles& a : {axisRoles(m, outer, inner), axisRoles(m, inner, outer)})
        for (int i : axisDeviations(m, a)) devs.push_back(i);
    return devs;
}

/// Equation of the paper a reading comes from, when the axis is the paper's (B along Y outer, C along Z inner).
std::string equation(const Dbb5AxisLine& l, bool inner, bool rotation, int k) {
    if (inner && l.axis == "C" && l.along == 2) return rotation ? (k == 0 ? "eq. (2)" : "eq. (1)") : "eq. (3)";
    if (!inner && l.axis == "B" && l.along == 1)
        return rotation ? (k == 0 ? "eq. (7)" : "eq. (6)") : "as eq. (3) for B";
    return rotation ? "the analogue of eq. (1)-(2), (6)-(7)" : "the analogue of eq. (3)";
}

std::vector<Dbb5FormulaValue> labelled(const Readings& r) {
    std::vector<Dbb5FormulaValue> out;
    const Dbb5Squareness& s = r.squareness;
    for (const auto& [p, q, v] : {std::tuple<char, char, double>{'X', 'Y', s.xy}, {'Y', 'Z', s.yz}, {'Z', 'X', s.zx}})
        out.push_back({fmt::format("90deg-angle({},{})", p, q),
                       fmt::format("out-of-squareness of +{} and +{}: 2*b2/LB of the {}{} circle (ISO 230-4); positive "
                                   "when they close in",
                                   p, q, p, q),
                       v, true});
    for (const auto& [l, inner] : {std::pair<const Dbb5AxisLine*, bool>{&r.outer, false}, {&r.inner, true}}) {
        const std::string other = inner ? r.outer.axis : r.inner.axis;
        for (int k : {l->first, l->second})
            out.push_back({l->positionName(k),
                           fmt::format("{} position of the {} axis line at {} = 0, relative to the machine axes ({} at "
                                       "0); {}",
                                       kLinearAxes[k], l->axis, kLinearAxes[l->along], other, equation(*l, inner, false, k)),
                           l->position[k], false});
        for (int k : {l->first, l->second})
            out.push_back({l->rotationName(k),
                           fmt::format("orientation of the {} axis line about {} relative to the machine axes ({} at 0), "
                                       "ISO 230-1 right-hand sign; {}",
                                       l->axis, kLinearAxes[k], other, equation(*l, inner, true, k)),
                           l->rotation[k], true});
    }
    return out;
}

}  // namespace

std::pair<std::string, std::string> dbb5TableAxes(const MachineModel& m, const Dbb5LocationOptions& o) {
    if (!o.outerAxis.empty() && !o.innerAxis.empty()) {
        for (const std::string& a : {o.outerAxis, o.innerAxis})
            if (m.axisLink(m.requireAxis(a)).kind != AxisKind::Rotary)
                throw ModelError(fmt::format("machine '{}': axis {} is not rotary", m.name, a));
        if (o.outerAxis == o.innerAxis) throw ModelError("the outer and inner rotary axes must differ");
        return {o.outerAxis, o.innerAxis};
    }
    std::vector<std::string> rotary;
    for (const Link& l : m.workpiece.links)
        if (l.kind == AxisKind::Rotary) rotary.push_back(l.name);
    if (rotary.size() != 2)
        throw ModelError(fmt::format("machine '{}' has {} rotary axes on the workpiece side; the DBB5 formulas need a "
                                     "tilting rotary table (two), or name the outer and inner axes",
                                     m.name, rotary.size()));
    return {o.outerAxis.empty() ? rotary[0] : o.outerAxis, o.innerAxis.empty() ? rotary[1] : o.innerAxis};
}

std::vector<int> dbb5LocationDeviations(const MachineModel& m, const Dbb5LocationOptions& o) {
    const auto axes = dbb5TableAxes(m, o);
    return modelDeviations(m, axes.first, axes.second);
}

Eigen::VectorXd dbb5GeometricReadings(const Kinematics& k, const std::string& outerAxis, const std::string& innerAxis) {
    const MachineModel& m = k.machine();
    const AxisVector q = AxisVector::Zero(m.axisCount());
    const auto motion = [&](const char* axis) {  // relative motion of the tool against the workpiece, bed frame
        AxisVector a = q;
        a[m.requireAxis(axis)] += 1.0;
        return Vec3((k.baseToTool(a).translation() - k.baseToTool(q).translation()) -
                    (k.baseToWorkpiece(a).translation() - k.baseToWorkpiece(q).translation()));
    };
    const Vec3 x = motion("X"), y = motion("Y"), z = motion("Z");
    const auto outOfSquare = [](const Vec3& a, const Vec3& b) {
        return kPi / 2 - std::atan2(a.cross(b).norm(), a.dot(b));
    };
    Dbb5Squareness s;
    s.xy = outOfSquare(x, y);
    s.yz = outOfSquare(y, z);
    s.zx = outOfSquare(z, x);
    const JointFrames frames = k.jointFrames(q);
    const auto line = [&](const std::string& axis) {
        const int i = m.requireAxis(axis);
        for (const JointFrame& f : frames)
            if (f.axis == i) return axisLineFromGeometry(axis, alongIndex(m, axis), f.point, f.direction);
        throw ModelError(fmt::format("machine '{}': axis {} has no joint frame", m.name, axis));
    };
    return pack(s, line(outerAxis), line(innerAxis));
}

Dbb5LocationResult dbb5LocationErrors(const MachineModel& m, const std::vector<Dbb5Run>& runs,
                                      const std::vector<BallbarTrace>& traces, const Dbb5LocationOptions& o) {
    if (runs.size() != traces.size()) throw ModelError(fmt::format("{} DBB5 runs but {} traces", runs.size(), traces.size()));
    if (o.refine < 0) throw ModelError("DBB5: the number of refinement steps must not be negative");
    const auto axes = dbb5TableAxes(m, o);
    const std::string outer = axes.first, inner = axes.second;
    const Roles roles = findRoles(m, runs, outer, inner);
    std::vector<const BallbarTrace*> measuredTraces;
    for (const BallbarTrace& t : traces) measuredTraces.push_back(&t);
    const Readings measured = readings(runs, measuredTraces, roles);
    const std::vector<int> devs = modelDeviations(m, outer, inner);

    Dbb5LocationResult res{DeviationSet(m), DeviationSet(m), labelled(measured), {}, outer, inner, measured.outer,
                           measured.inner, measured.squareness, {}, o.refine};
    for (int i : devs) res.identified.push_back(m.deviations[static_cast<size_t>(i)].name);
    for (size_t i = 0; i < runs.size(); ++i) res.runs.push_back({runs[i].name, evaluateCircularTest(traces[i], runs[i].LB)});
    const Eigen::VectorXd values = pack(measured.squareness, measured.outer, measured.inner);

    // Change of definitions: the model deviations whose geometry has the formulas' values (nearly linear: a few
    // Newton steps reach machine precision).
    const auto geometric = [&](const DeviationSet& s) { return dbb5GeometricReadings(Kinematics(m, s), outer, inner); };
    res.plain = refineReadings(m, devs, geometric, values, 4);
    if (o.refine == 0) {
        res.deviations = res.plain;
        return res;
    }
    // Refinement: the model deviations whose simulated runs give the measured readings. The runs' nominal commands
    // are solved once (Dbb5Observation), each simulation only evaluates the erroneous machine at them.
    std::vector<int> used;
    for (const AxisRoles* a : {&roles.outer, &roles.inner})
        for (int i : {a->pairFirst.lo, a->pairFirst.hi, a->pairSecond.lo, a->pairSecond.hi}) used.push_back(i);
    for (int i : {roles.xy, roles.yz, roles.zx}) used.push_back(i);
    std::vector<std::unique_ptr<Dbb5Observation>> observations(runs.size());
    for (int i : used)
        if (!observations[static_cast<size_t>(i)])
            observations[static_cast<size_t>(i)] =
                std::make_unique<Dbb5Observation>(m, runs[static_cast<size_t>(i)], traces[static_cast<size_t>(i)]);
    const auto simulated = [&](const DeviationSet& s) {
        const Kinematics k(m, s);
        std::vector<BallbarTrace> t(runs.size());
        std::vector<const BallbarTrace*> p(runs.size(), nullptr);
        for (size_t i = 0; i < runs.size(); ++i) {
            if (!observations[i]) continue;
            t[i].angleDeg = traces[i].angleDeg;
            t[i].dL.resize(traces[i].dL.size());
            observations[i]->predict(k, nullptr, t[i].dL.data());
            p[i] = &t[i];
        }
        const Readings r = readings(runs, p, roles);
        return Eigen::VectorXd(pack(r.squareness, r.outer, r.inner));
    };
    res.deviations = refineReadings(m, devs, simulated, values, o.refine);
    return res;
}

}  // namespace cnccomp::identification
