#include "cnccomp/identification/rtest_location_fits.hpp"

#include <cmath>

#include <fmt/format.h>

#include "cnccomp/circle_fit.hpp"
#include "cnccomp/error.hpp"
#include "cnccomp/identification/axis_line.hpp"
#include "cnccomp/identification/reading_refinement.hpp"

namespace cnccomp::identification {
using namespace cnccomp::measurement;

namespace {

using Vec2 = Eigen::Vector2d;

struct Roles {
    int xyc = -1, yza = -1, tiltPlus = -1, tiltMinus = -1;
    double phiPlus = 0, phiMinus = 0;  ///< deg
};

Roles findRoles(const std::vector<RtestRun>& runs, const RtestLocationOptions& o) {
    Roles r;
    for (size_t i = 0; i < runs.size(); ++i) {
        bool movesOuter = false, movesInner = false, other = false;
        double outerHeld = 0;
        for (const RotarySweep& s : runs[i].sweeps) {
            const bool moves = s.startDeg != s.endDeg;
            if (s.axis == o.outerAxis) {
                movesOuter = moves;
                outerHeld = s.startDeg;
            } else if (s.axis == o.innerAxis) {
                movesInner = moves;
            } else if (moves) {
                other = true;
            }
        }
        if (other) continue;
        const int idx = static_cast<int>(i);
        if (movesInner && !movesOuter) {
            if (std::abs(outerHeld) < 1e-9) {
                if (r.xyc < 0) r.xyc = idx;
            } else if (outerHeld > 0 && r.tiltPlus < 0) {
                r.tiltPlus = idx;
                r.phiPlus = outerHeld;
            } else if (outerHeld < 0 && r.tiltMinus < 0) {
                r.tiltMinus = idx;
                r.phiMinus = outerHeld;
            }
        } else if (movesOuter && !movesInner && r.yza < 0) {
            r.yza = idx;
        }
    }
    const auto need = [&](int i, const std::string& what) {
        if (i < 0) throw ModelError("the R-test location fits need a run " + what);
    };
    need(r.xyc, fmt::format("turning {} alone with {} at 0 (XYC)", o.innerAxis, o.outerAxis));
    need(r.yza, fmt::format("turning {} alone (YZA)", o.outerAxis));
    need(r.tiltPlus, fmt::format("turning {} with {} held at +φ", o.innerAxis, o.outerAxis));
    need(r.tiltMinus, fmt::format("turning {} with {} held at −φ", o.innerAxis, o.outerAxis));
    if (std::abs(r.phiPlus + r.phiMinus) > 1e-9)
        throw ModelError(fmt::format("R-test location fits: the tilted runs must be symmetric (+{:g} and {:g} deg)", r.phiPlus, r.phiMinus));
    if (std::abs(std::sin(2 * r.phiPlus * kDeg)) < 0.1)
        throw ModelError(fmt::format("R-test location fits: a tilt of {:g} deg cannot show the Y–Z squareness (sin 2φ too small)", r.phiPlus));
    return r;
}

/// Ball path (sign +1) or tool path (sign −1) in the bed frame.
std::vector<Vec3> path(const MachineModel& m, const RtestRun& run, const RtestTrace& t, const std::vector<Vec3>& d,
                       double sign) {
    const Kinematics nominal(m);
    const Vec3 nest = nominal.toolPoint(run.nestLength);
    std::vector<Vec3> p(d.size());
    for (size_t i = 0; i < d.size(); ++i) {
        const Pose bMt = nominal.baseToTool(t.commands[i]);
        p[i] = bMt * nest + sign * (bMt.linear() * d[i]);
    }
    return p;
}

std::vector<Vec2> project(const std::vector<Vec3>& p, int first, int second, double scaleFirst = 1.0) {
    std::vector<Vec2> out;
    out.reserve(p.size());
    for (const Vec3& v : p) out.emplace_back(v[first] * scaleFirst, v[second]);
    return out;
}

/// Eq. (2): (D45 − D135)/D0 of the tool path against the nominal path, both projected on (first, second).
double squarenessXYorZX(const std::vector<Vec3>& tool, const std::vector<Vec3>& nominal, int first, int second,
                        double scaleFirst, EllipseFit* fit) {
    const EllipseFit e = fitEllipse(project(tool, first, second, scaleFirst));
    const CircleFit c = fitCircle(project(nominal, first, second, scaleFirst));
    if (fit) *fit = e;
    return (ellipseDiameter(e, 45 * kDeg) - ellipseDiameter(e, 135 * kDeg)) / (2 * c.radius);
}



/// The plain formulas on one data set: fits of the raw trajectories, readings in the order of `devs`
/// (EC0Y EB0Z EA0Z, then the outer and the inner axis' four location errors).
struct Readings {
    Eigen::VectorXd values;
    Circle3Fit outer, inner;
    EllipseFit xy;
    double cXY = 0, cYZ = 0, cZX = 0;
};

Readings readings(const MachineModel& m, const std::vector<RtestRun>& runs, const std::vector<RtestTrace>& traces,
                  const Roles& r, const RtestLocationOptions& o, const std::vector<int>& devs) {
    const int ao = m.requireAxis(o.outerAxis), ai = m.requireAxis(o.innerAxis);
    const auto run = [&](int i) -> const RtestRun& { return runs[static_cast<size_t>(i)]; };
    const auto trace = [&](int i) -> const RtestTrace& { return traces[static_cast<size_t>(i)]; };
    const auto nominalPath = [&](int i) {
        return path(m, run(i), trace(i), std::vector<Vec3>(trace(i).d.size(), Vec3::Zero()), 1.0);
    };
    Readings out;
    DeviationSet set(m);
    // Squareness, eq. (2), on the tool paths.
    out.cXY = squarenessXYorZX(path(m, run(r.xyc), trace(r.xyc), trace(r.xyc).d, -1.0), nominalPath(r.xyc), 0, 1, 1.0, &out.xy);
    double sumZX = 0, diam[2] = {0, 0}, nominalDiam = 0;
    int k = 0;
    for (int i : {r.tiltPlus, r.tiltMinus}) {
        const double phi = (i == r.tiltPlus ? r.phiPlus : r.phiMinus) * kDeg;
        const auto tool = path(m, run(i), trace(i), trace(i).d, -1.0);
        const auto nom = nominalPath(i);
        sumZX += squarenessXYorZX(tool, nom, 2, 0, 1.0 / std::sin(phi), nullptr) / std::sin(phi);
        std::vector<double> phases;
        for (const AxisVector& q : trace(i).commands) phases.push_back(q[ai]);
        diam[k++] = 2 * fitEllipsePhases(project(tool, 1, 2), phases).a;
        nominalDiam += fitEllipsePhases(project(nom, 1, 2), phases).a;  // the mean of the two 2a
    }
    const double phi = r.phiPlus * kDeg;
    out.cZX = sumZX / 2 * std::sin(phi);
    out.cYZ = (diam[0] - diam[1]) / nominalDiam;
    set.values[m.deviations[static_cast<size_t>(devs[0])].offset] = out.cXY;                      // EC0Y
    set.values[m.deviations[static_cast<size_t>(devs[1])].offset] = sumZX / 2;                    // EB0Z
    set.values[m.deviations[static_cast<size_t>(devs[2])].offset] = -out.cYZ / std::sin(2 * phi);  // EA0Z
    // POPPE of the outer axis from the YZA ball path, of the inner axis from the XYC ball path.
    out.outer = fitCircle3(path(m, run(r.yza), trace(r.yza), trace(r.yza).d, 1.0), m.nominalDirection(ao));
    setAxisLine(m, set, ao, trace(r.yza).commands.front(), out.outer.center, out.outer.normal,
                std::vector<int>(devs.begin() + 3, devs.begin() + 7));
    out.inner = fitCircle3(path(m, run(r.xyc), trace(r.xyc), trace(r.xyc).d, 1.0), m.nominalDirection(ai));
    setAxisLine(m, set, ai, trace(r.xyc).commands.front(), out.inner.center, out.inner.normal,
                std::vector<int>(devs.begin() + 7, devs.end()));
    out.values.resize(static_cast<Eigen::Index>(devs.size()));
    for (size_t i = 0; i < devs.size(); ++i)
        out.values[static_cast<Eigen::Index>(i)] = set.values[m.deviations[static_cast<size_t>(devs[i])].offset];
    return out;
}

}  // namespace

RtestLocationResult rtestLocationFits(const MachineModel& m, const std::vector<RtestRun>& runs,
                              const std::vector<RtestTrace>& traces, const RtestLocationOptions& o) {
    if (runs.size() != traces.size()) throw ModelError(fmt::format("{} R-test runs but {} traces", runs.size(), traces.size()));
    if (o.refine < 0) throw ModelError("R-test location fits: the number of refinement steps must not be negative");
    const Roles r = findRoles(runs, o);
    const std::string A = o.outerAxis, C = o.innerAxis;
    std::vector<int> devs;
    for (const std::string& n : {std::string("EC0Y"), std::string("EB0Z"), std::string("EA0Z"), "EY0" + A, "EZ0" + A,
                                 "EB0" + A, "EC0" + A, "EX0" + C, "EY0" + C, "EA0" + C, "EB0" + C}) {
        const int i = m.deviationIndex(n);
        if (i < 0) throw ModelError(fmt::format("machine '{}' has no deviation '{}' (the R-test location fits identify it)", m.name, n));
        devs.push_back(i);
    }
    const Readings measured = readings(m, runs, traces, r, o, devs);
    const auto simulated = [&](const DeviationSet& s) {
        const Kinematics k(m, s);
        std::vector<RtestTrace> t;
        for (size_t i = 0; i < runs.size(); ++i) t.push_back(simulateRtest(k, runs[i], traces[i].commands));
        return readings(m, runs, t, r, o, devs).values;
    };
    RtestLocationResult res{refineReadings(m, devs, simulated, measured.values, o.refine),
                      refineReadings(m, devs, simulated, measured.values, 0),
                      measured.outer, measured.inner, measured.xy, measured.cXY, measured.cYZ, measured.cZX,
                      r.phiPlus, o.refine};
    return res;
}

VolumetricAlongRun volumetricErrorAlongRun(const MachineModel& m, const DeviationSet& identified, const RtestRun& run,
                                     const RtestTrace& trace) {
    VolumetricAlongRun v;
    v.measured = trace.d;
    v.predicted = simulateRtest(Kinematics(m, identified), run, trace.commands).d;
    double ss = 0, sm = 0;
    for (size_t i = 0; i < v.measured.size(); ++i) {
        const double e = (v.measured[i] - v.predicted[i]).norm();
        ss += e * e;
        sm += v.measured[i].squaredNorm();
        v.maxResidual = std::max(v.maxResidual, e);
    }
    const double n = static_cast<double>(std::max<size_t>(v.measured.size(), 1));
    v.rmsResidual = std::sqrt(ss / n);
    v.rmsMeasured = std::sqrt(sm / n);
    return v;
}

}  // namespace cnccomp::identification
