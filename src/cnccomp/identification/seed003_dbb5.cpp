#include "cnccomp/identification/seed003_dbb5.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/identification/axis_line.hpp"
#include "cnccomp/identification/reading_refinement.hpp"

namespace cnccomp {

namespace {

double held(const Dbb5Run& r, const std::string& axis) {
    for (const auto& [a, v] : r.hold)
        if (a == axis) return v;
    return 0.0;
}

/// Two runs of one role, at the lowest and highest coordinate.
struct Pair {
    int lo = -1, hi = -1;
    double cLo = 0, cHi = 0;
    int axisOfBar = 0;  ///< 0 x, 1 y, 2 z
};

void consider(Pair& p, int run, double coord) {
    if (p.lo < 0 || coord < p.cLo) {
        p.lo = run;
        p.cLo = coord;
    }
    if (p.hi < 0 || coord > p.cHi) {
        p.hi = run;
        p.cHi = coord;
    }
}

struct Roles {
    int xy = -1, yz = -1, zx = -1;
    Pair cx, cy, ay, az;
};

Roles findRoles(const MachineModel& m, const std::vector<Dbb5Run>& runs, const Seed003Options& o) {
    Roles r;
    r.cx.axisOfBar = 0;
    r.cy.axisOfBar = 1;
    r.ay.axisOfBar = 1;
    r.az.axisOfBar = 2;
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
        const Vec3 u = run.barDirection.normalized();
        int k = 0;
        u.cwiseAbs().maxCoeff(&k);
        const AxisVector q = dbb5SetupCommands(m, run);
        const Vec3 ballBed = nominal.baseToWorkpiece(q) * run.ball;
        if (run.axis == o.innerAxis && std::abs(held(run, o.outerAxis)) < 1e-9) {
            if (k == 0) consider(r.cx, idx, ballBed.z());
            if (k == 1) consider(r.cy, idx, ballBed.z());
        } else if (run.axis == o.outerAxis && std::abs(held(run, o.innerAxis)) < 1e-9) {
            if (k == 1) consider(r.ay, idx, ballBed.x());
            if (k == 2) consider(r.az, idx, ballBed.x());
        }
    }
    if (r.xy < 0 || r.yz < 0 || r.zx < 0) throw ModelError("seed 003 needs a linear circle in each plane XY, YZ and ZX");
    const auto need = [](const Pair& p, const std::string& what) {
        if (p.lo < 0 || p.hi < 0 || !(p.cHi - p.cLo > 1e-6))
            throw ModelError(fmt::format("seed 003 needs two {} runs at different ball positions", what));
    };
    need(r.cx, fmt::format("{} runs with the bar along X ({} at 0)", o.innerAxis, o.outerAxis));
    need(r.cy, fmt::format("{} runs with the bar along Y ({} at 0)", o.innerAxis, o.outerAxis));
    need(r.ay, fmt::format("{} runs with the bar along Y ({} at 0)", o.outerAxis, o.innerAxis));
    need(r.az, fmt::format("{} runs with the bar along Z ({} at 0)", o.outerAxis, o.innerAxis));
    return r;
}

/// The plain formulas on one data set; readings in the order EC0Y EA0Z EB0Z, outer axis (EY0 EZ0 EB0 EC0), inner
/// axis (EX0 EY0 EA0 EB0).
Eigen::VectorXd readings(const MachineModel& m, const std::vector<Dbb5Run>& runs, const std::vector<BallbarTrace>& traces,
                         const Roles& r, const Seed003Options& o, const std::vector<int>& devs, Seed003Numbers& n) {
    const auto run = [&](int i) -> const Dbb5Run& { return runs[static_cast<size_t>(i)]; };
    const auto iso = [&](int i) { return evaluateCircularTest(traces[static_cast<size_t>(i)], run(i).LB); };
    // Centre shift along the bar's main axis: c = −r/(u·e).
    const auto centre = [&](int i, int axis) { return -iso(i).meanRadialError / run(i).barDirection.normalized()[axis]; };
    DeviationSet set(m);
    n.b2XY = iso(r.xy).b2;
    n.b2YZ = iso(r.yz).b2;
    n.b2ZX = iso(r.zx).b2;
    set.values[m.deviations[static_cast<size_t>(devs[0])].offset] = 2 * n.b2XY / run(r.xy).LB;
    set.values[m.deviations[static_cast<size_t>(devs[1])].offset] = -2 * n.b2YZ / run(r.yz).LB;
    set.values[m.deviations[static_cast<size_t>(devs[2])].offset] = 2 * n.b2ZX / run(r.zx).LB;
    // Inner axis, eq. (1)–(3).
    n.Z1 = r.cx.cLo;
    n.Z2 = r.cx.cHi;
    n.cx1 = centre(r.cx.lo, 0);
    n.cx2 = centre(r.cx.hi, 0);
    n.cy1 = centre(r.cy.lo, 1);
    n.cy2 = centre(r.cy.hi, 1);
    n.betaZ = (n.cx2 - n.cx1) / (r.cx.cHi - r.cx.cLo);
    n.alphaZ = -(n.cy2 - n.cy1) / (r.cy.cHi - r.cy.cLo);
    n.dx = n.cx1 - n.betaZ * r.cx.cLo;
    n.dy = n.cy1 + n.alphaZ * r.cy.cLo;
    const int ao = m.requireAxis(o.outerAxis), ai = m.requireAxis(o.innerAxis);
    setAxisLine(m, set, ai, dbb5SetupCommands(m, run(r.cx.lo)), Vec3(n.dx, n.dy, 0), Vec3(n.betaZ, -n.alphaZ, 1),
                std::vector<int>(devs.begin() + 7, devs.end()));
    // Outer axis, eq. (6)–(7) for A.
    n.x1 = r.ay.cLo;
    n.x2 = r.ay.cHi;
    n.cyA1 = centre(r.ay.lo, 1);
    n.cyA2 = centre(r.ay.hi, 1);
    n.czA1 = centre(r.az.lo, 2);
    n.czA2 = centre(r.az.hi, 2);
    const double ecA = (n.cyA2 - n.cyA1) / (r.ay.cHi - r.ay.cLo);
    const double ebA = -(n.czA2 - n.czA1) / (r.az.cHi - r.az.cLo);
    const double eyA = n.cyA1 - ecA * r.ay.cLo;
    const double ezA = n.czA1 + ebA * r.az.cLo;
    setAxisLine(m, set, ao, dbb5SetupCommands(m, run(r.ay.lo)), Vec3(0, eyA, ezA), Vec3(1, ecA, -ebA),
                std::vector<int>(devs.begin() + 3, devs.begin() + 7));
    Eigen::VectorXd v(static_cast<Eigen::Index>(devs.size()));
    for (size_t i = 0; i < devs.size(); ++i) v[static_cast<Eigen::Index>(i)] = set.values[m.deviations[static_cast<size_t>(devs[i])].offset];
    return v;
}

}  // namespace

Seed003Result seed003Formulas(const MachineModel& m, const std::vector<Dbb5Run>& runs,
                              const std::vector<BallbarTrace>& traces, const Seed003Options& o) {
    if (runs.size() != traces.size()) throw ModelError(fmt::format("{} DBB5 runs but {} traces", runs.size(), traces.size()));
    if (o.refine < 0) throw ModelError("seed 003: the number of refinement steps must not be negative");
    const Roles r = findRoles(m, runs, o);
    const std::string A = o.outerAxis, C = o.innerAxis;
    std::vector<int> devs;
    for (const std::string& n : {std::string("EC0Y"), std::string("EA0Z"), std::string("EB0Z"), "EY0" + A, "EZ0" + A,
                                 "EB0" + A, "EC0" + A, "EX0" + C, "EY0" + C, "EA0" + C, "EB0" + C}) {
        const int i = m.deviationIndex(n);
        if (i < 0) throw ModelError(fmt::format("machine '{}' has no deviation '{}' (seed 003 identifies it)", m.name, n));
        devs.push_back(i);
    }
    Seed003Result res{DeviationSet(m), DeviationSet(m), {}, {}, o.refine};
    for (size_t i = 0; i < runs.size(); ++i) res.runs.push_back({runs[i].name, evaluateCircularTest(traces[i], runs[i].LB)});
    const Eigen::VectorXd measured = readings(m, runs, traces, r, o, devs, res.numbers);
    const auto simulated = [&](const DeviationSet& s) {
        const Kinematics k(m, s);
        std::vector<BallbarTrace> t;
        for (const Dbb5Run& run : runs) t.push_back(simulateDbb5(k, run));
        Seed003Numbers scratch;
        return readings(m, runs, t, r, o, devs, scratch);
    };
    res.plain = refineReadings(m, devs, simulated, measured, 0);
    res.deviations = refineReadings(m, devs, simulated, measured, o.refine);
    return res;
}

}  // namespace cnccomp
