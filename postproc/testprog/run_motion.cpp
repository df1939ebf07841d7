#include "postproc/testprog/run_motion.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/identification/dbb5_run.hpp"
#include "cnccomp/identification/rtest_run.hpp"
#include "cnccomp/kinematics.hpp"

namespace cnccomp::postproc::testprog {
using namespace cnccomp::identification;
using namespace cnccomp::measurement;

const char* runKindName(RunKind k) {
    switch (k) {
        case RunKind::Ballbar: return "ball bar";
        case RunKind::AbsoluteBallbar: return "absolute ball bar";
        case RunKind::Rtest: return "R-test";
        case RunKind::Dbb5: return "DBB5";
        case RunKind::LinearCircle: return "linear circle";
    }
    return "?";
}

namespace {

std::string vec(const Vec3& v) { return fmt::format("({:.3f}, {:.3f}, {:.3f})", v.x(), v.y(), v.z()); }

/// Sweep points of an angular sweep: the samples, then the end angle when it is not one (closing point of a turn).
void sweepPoints(RunMotion& r, const std::vector<double>& samples, double endDeg) {
    r.points = samples;
    r.sampleCount = samples.size();
    if (samples.empty() || std::abs(samples.back() - endDeg) > 1e-9) r.points.push_back(endDeg);
}

std::string sweepNote(const std::string& axis, double start, double end, double step, size_t samples) {
    return fmt::format("sweep: {} from {:g} to {:g} deg in steps of {:g} deg, {} samples", axis, start, end, step, samples);
}

/// Tool-side ball and its partner in the workpiece and bed frames at the setup commands (nominal machine).
void ballNotes(RunMotion& r, const Kinematics& k, const Vec3& toolBall, const Vec3& partner, const char* partnerName) {
    const AxisVector& q = r.setup;
    r.notes.push_back(fmt::format("tool-side ball: {:.3f} mm along the tool direction from the last tool frame", r.toolLength));
    r.notes.push_back(fmt::format("{}: workpiece frame {} mm, bed frame {} mm at the setup pose", partnerName, vec(partner),
                                  vec(k.baseToWorkpiece(q) * partner)));
    const Vec3 tip0 = k.toolPointInWorkpiece(r.at(r.points.front()), toolBall);
    const Vec3 bar = tip0 - partner;
    if (bar.norm() > 1e-9)
        r.notes.push_back(fmt::format("bar direction at the first sample ({} -> tool-side ball, workpiece frame): {}",
                                      partnerName, vec(bar.normalized())));
}

RunMotion ballbarMotion(const MachineModel& m, const Kinematics& k, const BallbarRun& run, bool absolute) {
    RunMotion r;
    r.name = run.name;
    r.kind = absolute ? RunKind::AbsoluteBallbar : RunKind::Ballbar;
    r.ballbar = &run;
    r.setup = setupCommands(m, run);
    r.at = [&m, &run](double t) { return runCommands(m, run, t * kDeg); };
    sweepPoints(r, run.anglesDeg(), run.endDeg);
    r.toolLength = run.RB;
    const std::string axis = rotatesHead(run.test) ? run.headAxis : run.tableAxis;
    r.parameter = axis + " angle (deg)";
    r.notes.push_back(fmt::format("run type {}, [MultiTasking] Table 2{}", testName(run.test),
                                  absolute ? "; absolute bar: Ball 2 at its nominal position, [FanWuLi] section 3.1" : ""));
    r.notes.push_back(fmt::format("LB = {:g} mm (bar length), RB = {:g} mm (tool length), RC = {:g} mm, ZC = {:g} mm", run.LB,
                                  run.RB, run.RC, run.ZC));
    if (!run.toolBallOffset.isZero() || !run.workBallOffset.isZero())
        r.notes.push_back(fmt::format("mounting offsets: tool ball {} mm, work ball {} mm", vec(run.toolBallOffset),
                                      vec(run.workBallOffset)));
    r.notes.push_back(sweepNote(axis, run.startDeg, run.endDeg, run.stepDeg, r.sampleCount));
    const Vec3 tBall = k.toolPoint(run.RB, run.toolBallOffset);
    const Vec3 wBall = k.toolPointInWorkpiece(r.setup, tBall) + run.workBallOffset;
    ballNotes(r, k, tBall, wBall, absolute ? "Ball 2 (pivot)" : "W-side (pivot) ball");
    r.setupAction = absolute ? "CHECK THAT BALL 2 SITS ON ITS NOMINAL POSITION UNDER THE TOOL-SIDE BALL"
                             : "SET THE W-SIDE (PIVOT) BALL ON THE TOOL-SIDE BALL HERE AND FIX IT";
    r.captureAction = "MOUNT THE BAR, START THE BALL-BAR DATA CAPTURE, THEN CYCLE START";
    return r;
}

RunMotion dbb5Motion(const MachineModel& m, const Kinematics& k, const Dbb5Run& run) {
    RunMotion r;
    r.name = run.name;
    r.kind = RunKind::Dbb5;
    r.dbb5 = &run;
    r.setup = dbb5SetupCommands(m, run);
    r.at = [&m, &run](double t) { return dbb5Commands(m, run, t); };
    sweepPoints(r, run.anglesDeg(), run.endDeg);
    r.toolLength = run.toolLength;
    const bool linear = run.kind == Dbb5Run::Kind::LinearCircle;
    r.parameter = linear ? run.plane + " circle angle (deg)" : run.axis + " angle (deg)";
    r.notes.push_back(linear ? fmt::format("run type DBB5 linear circle in {}, [IbarakiDBB5], ISO 230-4", run.plane)
                             : fmt::format("run type DBB5 rotary circle: {} turns, bar along {} in the bed frame, [IbarakiDBB5]",
                                           run.axis, vec(run.barDirection.normalized())));
    std::string hold;
    for (const auto& [axis, deg] : run.hold) hold += fmt::format(" {}={:g}", axis, deg);
    r.notes.push_back(fmt::format("LB = {:g} mm (bar length), tool length {:g} mm, table ball {} mm{}", run.LB, run.toolLength,
                                  vec(run.ball), hold.empty() ? "" : ", held:" + hold));
    r.notes.push_back(sweepNote(linear ? run.plane + " angle" : run.axis, run.startDeg, run.endDeg, run.stepDeg, r.sampleCount));
    const Vec3 tBall = k.toolPoint(run.toolLength);
    ballNotes(r, k, tBall, k.toolPointInWorkpiece(r.setup, tBall), "table ball");
    r.setupAction = "SET THE TABLE BALL ON THE SPINDLE BALL HERE AND FIX IT";
    r.captureAction = "MOUNT THE BAR, START THE DBB DATA CAPTURE, THEN CYCLE START";
    return r;
}

RunMotion rtestMotion(const MachineModel& m, const Kinematics& k, const RtestRun& run) {
    RunMotion r;
    r.name = run.name;
    r.kind = RunKind::Rtest;
    r.rtest = &run;
    auto poses = std::make_shared<std::vector<AxisVector>>(rtestCommands(m, run));
    r.setup = poses->front();
    r.at = [poses](double t) {
        const double last = static_cast<double>(poses->size() - 1);
        t = std::clamp(t, 0.0, last);
        const size_t i = std::min(static_cast<size_t>(std::floor(t)), poses->size() - 1);
        if (i + 1 >= poses->size()) return (*poses)[i];
        const double f = t - static_cast<double>(i);
        return AxisVector((1 - f) * (*poses)[i] + f * (*poses)[i + 1]);
    };
    for (size_t i = 0; i < poses->size(); ++i) r.points.push_back(static_cast<double>(i));
    r.sampleCount = r.points.size();
    r.continuous = false;
    r.toolLength = run.nestLength;
    r.parameter = "pose";
    r.notes.push_back("run type R-test, [Moravek2019] / [RotaryTableModel]: stop-and-go poses, the nest follows the ball on the nominal machine");
    r.notes.push_back(fmt::format("ball {} mm (workpiece frame), nest {:g} mm along the tool direction, {} poses", vec(run.ball),
                                  run.nestLength, r.sampleCount));
    for (const RotarySweep& s : run.sweeps)
        r.notes.push_back(s.startDeg == s.endDeg ? fmt::format("{} held at {:g} deg", s.axis, s.startDeg)
                                                 : fmt::format("sweep: {} from {:g} to {:g} deg", s.axis, s.startDeg, s.endDeg));
    r.notes.push_back(fmt::format("ball in the bed frame at the first pose: {} mm",
                                  vec(k.baseToWorkpiece(r.setup) * run.ball)));
    r.setupAction = "CENTRE THE R-TEST NEST ON THE BALL HERE (ALL SENSORS NEAR MID RANGE), THEN ZERO THE SENSORS";
    r.captureAction = "START THE R-TEST DATA CAPTURE (ONE READING PER DWELL), THEN CYCLE START";
    return r;
}

RunMotion circleMotion(const MachineModel& m, const Kinematics& k, const LinearCircleRun& run) {
    RunMotion r;
    r.name = run.name;
    r.kind = RunKind::LinearCircle;
    r.circle = &run;
    r.setup = linearCircleCentreCommands(m, run);
    r.at = [&m, &run](double t) { return linearCircleCommands(m, run, t); };
    r.points = run.dataAnglesDeg();
    r.sampleCount = r.points.size();
    r.toolLength = run.toolLength;
    const char* plane = linearPlaneName(run.plane);
    const std::array<char, 2> ax = linearPlaneAxes(run.plane);
    r.parameter = fmt::format("{} circle angle (deg, from +{} towards +{})", plane, ax[0], ax[1]);
    r.notes.push_back(fmt::format("run type ball-bar circle of the linear axes in {} (ISO 230-4), radius {:g} mm = bar length",
                                  plane, run.radius));
    r.notes.push_back(fmt::format("circle centre (commands X Y Z): {} mm; tool ball {:g} mm along the tool direction", vec(run.centre),
                                  run.toolLength));
    r.notes.push_back(fmt::format("data arc: {:g} deg from {:g} to {:g} deg, samples every {:g} deg, feed {:g} mm/min, overshoot "
                                  "{:g} deg at each end",
                                  run.arcDeg, run.startDeg, run.endDeg(), run.stepDeg, run.capture.feed, run.capture.overshootDeg));
    std::string hold;
    for (const auto& [axis, deg] : run.hold) hold += fmt::format(" {}={:g}", axis, deg);
    if (!hold.empty()) r.notes.push_back("held:" + hold);
    r.notes.push_back(fmt::format("pivot (centre) ball at the setup pose, bed frame: {} mm",
                                  vec(k.baseToWorkpiece(r.setup) * k.toolPointInWorkpiece(r.setup, k.toolPoint(run.toolLength)))));
    r.setupAction = "SET THE PIVOT (CENTRE) BALL UNDER THE TOOL BALL HERE AND FIX IT";
    r.captureAction = "MOUNT THE BAR, START THE BALL-BAR DATA CAPTURE, THEN CYCLE START";
    return r;
}

}  // namespace

std::vector<RunMotion> planMotions(const MachineModel& m, const MeasurementPlan& plan) {
    const Kinematics k(m);
    std::vector<RunMotion> out;
    for (const BallbarRun& r : plan.runs) out.push_back(ballbarMotion(m, k, r, false));
    for (const BallbarRun& r : plan.absoluteRuns) out.push_back(ballbarMotion(m, k, r, true));
    for (const Dbb5Run& r : plan.dbb5Runs) out.push_back(dbb5Motion(m, k, r));
    for (const RtestRun& r : plan.rtestRuns) out.push_back(rtestMotion(m, k, r));
    for (const LinearCircleRun& r : plan.circleRuns) out.push_back(circleMotion(m, k, r));
    return out;
}

PathShape analysePath(const MachineModel& m, const RunMotion& motion, double from, double to, double step) {
    PathShape s;
    const int n = m.axisCount();
    // Evaluation points: every step and half-way between, in sweep order.
    std::vector<double> ts;
    const double dir = to >= from ? 1.0 : -1.0;
    const double span = std::abs(to - from);
    const long steps = std::max(1L, static_cast<long>(std::ceil(span / std::abs(step) - 1e-9)));
    for (long i = 0; i <= 2 * steps; ++i) ts.push_back(from + dir * std::min(span, i * std::abs(step) / 2));
    std::vector<AxisVector> p;
    p.reserve(ts.size());
    for (double t : ts) p.push_back(m.toController(motion.at(t)));
    const auto moves = [&](int a, double tol) {
        for (const AxisVector& q : p)
            if (std::abs(q[a] - p.front()[a]) > tol) return true;
        return false;
    };
    const int X = m.axisIndex("X"), Y = m.axisIndex("Y"), Z = m.axisIndex("Z");
    for (int a = 0; a < n; ++a) {
        if (m.axisLink(a).kind == AxisKind::Rotary) s.rotaryMoves |= moves(a, 1e-12);
        else s.linearMoves |= moves(a, 1e-9);
    }
    if (!s.linearMoves || ts.size() < 3 || span == 0) return s;
    // Rotary axes linear in t.
    for (int a = 0; a < n; ++a) {
        if (m.axisLink(a).kind != AxisKind::Rotary) continue;
        const double k = (p.back()[a] - p.front()[a]) / (ts.back() - ts.front());
        for (size_t i = 0; i < p.size(); ++i)
            if (std::abs(p[i][a] - (p.front()[a] + k * (ts[i] - ts.front()))) > 1e-11) return s;
    }
    // One principal plane: the other linear axes stand still.
    struct Plane {
        int code, a0, a1, normal;
    };
    const Plane planes[] = {{17, X, Y, Z}, {18, Z, X, Y}, {19, Y, Z, X}};
    for (const Plane& pl : planes) {
        if (pl.a0 < 0 || pl.a1 < 0) continue;
        bool others = false;
        for (int a = 0; a < n; ++a)
            if (a != pl.a0 && a != pl.a1 && m.axisLink(a).kind != AxisKind::Rotary) others |= moves(a, 1e-9);
        if (others) continue;
        // Circumcentre of three points spread over the sweep.
        const size_t i1 = 0, i2 = p.size() / 3, i3 = (2 * p.size()) / 3;
        const Eigen::Vector2d A(p[i1][pl.a0], p[i1][pl.a1]), B(p[i2][pl.a0], p[i2][pl.a1]), C(p[i3][pl.a0], p[i3][pl.a1]);
        const double d = 2 * (A.x() * (B.y() - C.y()) + B.x() * (C.y() - A.y()) + C.x() * (A.y() - B.y()));
        if (std::abs(d) < 1e-12) return s;
        const double a2 = A.squaredNorm(), b2 = B.squaredNorm(), c2 = C.squaredNorm();
        const Eigen::Vector2d c((a2 * (B.y() - C.y()) + b2 * (C.y() - A.y()) + c2 * (A.y() - B.y())) / d,
                                (a2 * (C.x() - B.x()) + b2 * (A.x() - C.x()) + c2 * (B.x() - A.x())) / d);
        const double R = (A - c).norm();
        double angle = 0, prev = std::atan2(A.y() - c.y(), A.x() - c.x());
        std::vector<double> phi{0.0};
        for (size_t i = 1; i < p.size(); ++i) {
            const Eigen::Vector2d P(p[i][pl.a0], p[i][pl.a1]);
            if (std::abs((P - c).norm() - R) > 1e-7) return s;
            const double now = std::atan2(P.y() - c.y(), P.x() - c.x());
            angle += std::remainder(now - prev, 2 * kPi);
            prev = now;
            phi.push_back(angle);
        }
        const double rate = phi.back() / (ts.back() - ts.front());
        for (size_t i = 0; i < p.size(); ++i)
            if (std::abs(phi[i] - rate * (ts[i] - ts.front())) * R > 1e-7) return s;
        s.circle = true;
        s.plane = pl.code;
        s.axis0 = pl.a0;
        s.axis1 = pl.a1;
        s.c0 = c.x();
        s.c1 = c.y();
        s.radius = R;
        s.rate = rate;
        return s;
    }
    return s;
}

}  // namespace cnccomp::postproc::testprog
