#include "cnccomp/ballbar.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "cnccomp/circle_fit.hpp"
#include "cnccomp/error.hpp"
#include "cnccomp/measurement/sweep.hpp"

namespace cnccomp {
using namespace cnccomp::measurement;

namespace {
struct TestInfo {
    BallbarTest test;
    std::string_view name;
    bool head;
};
constexpr TestInfo kTests[] = {
    {BallbarTest::BX, "B-X", true},           {BallbarTest::BY, "B-Y", true},
    {BallbarTest::BZ, "B-Z", true},           {BallbarTest::CRadial, "C-radial", false},
    {BallbarTest::CTangential, "C-tangential", false}, {BallbarTest::CAxial, "C-axial", false},
    {BallbarTest::CX, "C-X", false},          {BallbarTest::CY, "C-Y", false},
    {BallbarTest::CZ, "C-Z", false},          {BallbarTest::BRadial, "B-radial", true},
    {BallbarTest::BTangential, "B-tangential", true}, {BallbarTest::BAxial, "B-axial", true},
};
const TestInfo& info(BallbarTest t) {
    for (const auto& i : kTests)
        if (i.test == t) return i;
    throw ModelError("unknown ball-bar test");
}
}  // namespace

std::string_view testName(BallbarTest t) { return info(t).name; }
bool rotatesHead(BallbarTest t) { return info(t).head; }

std::optional<BallbarTest> parseTest(std::string_view s) {
    for (const auto& i : kTests)
        if (i.name == s) return i.test;
    return std::nullopt;
}

void BallbarRun::validate() const {
    const auto bad = [&](const std::string& what) {
        throw ModelError(fmt::format("run '{}' ({}): {}", name, testName(test), what));
    };
    for (double v : {LB, RB, RC, ZC, startDeg, endDeg, stepDeg})
        if (!std::isfinite(v)) bad("geometry values must be finite numbers");
    if (!(LB > 0)) bad("ball bar length LB must be positive");
    if (!(RB > 0)) bad("tool length RB must be positive");
    if (stepDeg == 0) bad("angle step must not be zero");
    if ((endDeg - startDeg) / stepDeg < 0) bad("angle step points away from the end angle");
    if (std::abs((endDeg - startDeg) / stepDeg) > 1e7) bad("more than 10 million samples");
    if (!toolBallOffset.allFinite() || !workBallOffset.allFinite()) bad("ball offsets must be finite");
}

std::vector<double> BallbarRun::anglesDeg() const {
    validate();
    return sweepAnglesDeg(startDeg, endDeg, stepDeg);
}

namespace {

struct RunAxes {
    int x, y, z, head, table;
};

RunAxes runAxes(const MachineModel& m, const BallbarRun& run) {
    RunAxes a{m.requireAxis("X"), m.requireAxis("Y"), m.requireAxis("Z"), -1, -1};
    if (rotatesHead(run.test)) {
        a.head = m.requireAxis(run.headAxis);
        a.table = m.axisIndex(run.tableAxis);
    } else {
        a.table = m.requireAxis(run.tableAxis);
        a.head = m.axisIndex(run.headAxis);
    }
    return a;
}

}  // namespace

AxisVector setupCommands(const MachineModel& m, const BallbarRun& run) {
    const RunAxes ax = runAxes(m, run);
    AxisVector q = AxisVector::Zero(m.axisCount());
    q[ax.x] = rotatesHead(run.test) ? 0.0 : run.RC;  // eq. (11) vs eq. (12)
    q[ax.z] = run.ZC + run.RB;
    return q;
}

AxisVector runCommands(const MachineModel& m, const BallbarRun& run, double a) {
    const RunAxes ax = runAxes(m, run);
    AxisVector q = AxisVector::Zero(m.axisCount());
    const double LB = run.LB, RB = run.RB, RC = run.RC, ZC = run.ZC;
    const double s = std::sin(a), c = std::cos(a);
    double X = 0, Y = 0, Z = 0;
    switch (run.test) {  // [MultiTasking] Table 2
        case BallbarTest::BRadial: X = (LB + RB) * s; Z = ZC + (LB + RB) * c; break;
        case BallbarTest::BTangential: {
            const double RBT = std::hypot(RB, LB), psi = std::atan2(LB, RB);
            X = RBT * std::sin(a + psi); Z = ZC + RBT * std::cos(a + psi); break;
        }
        case BallbarTest::BAxial: X = RB * s; Y = LB; Z = ZC + RB * c; break;
        case BallbarTest::CRadial: X = (RC - LB) * c; Y = (RC - LB) * s; Z = ZC + RB; break;
        case BallbarTest::CTangential: {
            const double RCT = std::hypot(RC, LB), psi = std::atan2(LB, RC);
            X = RCT * std::cos(a + psi); Y = RCT * std::sin(a + psi); Z = ZC + RB; break;
        }
        case BallbarTest::CAxial: X = RC * c; Y = RC * s; Z = ZC + LB + RB; break;
        case BallbarTest::BX: X = LB + RB * s; Z = ZC + RB * c; break;
        case BallbarTest::BY: X = RB * s; Y = LB; Z = ZC + RB * c; break;
        case BallbarTest::BZ: X = RB * s; Z = LB + ZC + RB * c; break;
        case BallbarTest::CX: X = LB + RC * c; Y = RC * s; Z = ZC + RB; break;
        case BallbarTest::CY: X = RC * c; Y = LB + RC * s; Z = ZC + RB; break;
        case BallbarTest::CZ: X = RC * c; Y = RC * s; Z = LB + ZC + RB; break;
    }
    q[ax.x] = X;
    q[ax.y] = Y;
    q[ax.z] = Z;
    if (rotatesHead(run.test)) q[ax.head] = a;
    else q[ax.table] = a;
    return q;
}

BallbarTrace simulateRun(const Kinematics& k, const BallbarRun& run, const CommandMap& drive) {
    const MachineModel& m = k.machine();
    const std::vector<double> angles = run.anglesDeg();
    const Vec3 tBall = k.toolPoint(run.RB, run.toolBallOffset);
    const AxisVector q0 = drive ? drive(setupCommands(m, run)) : setupCommands(m, run);
    try {
        k.checkTravel(q0);
    } catch (const ModelError& e) {
        throw ModelError(fmt::format("run '{}' setup: {}", run.name, e.what()));
    }
    // The W-side ball is set where the T-side ball is (eq. (11)–(13)), plus its mounting offset (eq. (16)).
    const Vec3 wBall = k.toolPointInWorkpiece(q0, tBall) + run.workBallOffset;
    BallbarTrace t;
    t.angleDeg = angles;
    t.dL.resize(angles.size());
    for (size_t i = 0; i < angles.size(); ++i) {
        const AxisVector q = drive ? drive(runCommands(m, run, angles[i] * kDeg)) : runCommands(m, run, angles[i] * kDeg);
        try {
            k.checkTravel(q);
        } catch (const ModelError& e) {
            throw ModelError(fmt::format("run '{}' at {:g} deg: {}", run.name, angles[i], e.what()));
        }
        t.dL[i] = (k.toolPointInWorkpiece(q, tBall) - wBall).norm() - run.LB;  // eq. (14)
    }
    return t;
}

RunPlane runPlane(const MachineModel& m, const BallbarRun& run) {
    const int axis = rotatesHead(run.test) ? m.requireAxis(run.headAxis) : m.requireAxis(run.tableAxis);
    const Vec3 d = m.nominalDirection(axis);
    int k = 0;
    d.cwiseAbs().maxCoeff(&k);
    const Vec3 e = Vec3::Unit((k + 1) % 3);
    RunPlane p;
    p.u = (e - e.dot(d) * d).normalized();
    p.v = d.cross(p.u);
    p.normalIndex = k;
    return p;
}

Vec3 traceEccentricity(const MachineModel& m, const BallbarRun& run, const BallbarTrace& trace) {
    if (trace.angleDeg.size() != trace.dL.size() || trace.dL.size() < 3)
        throw ModelError(fmt::format("run '{}': a trace needs at least three samples", run.name));
    std::vector<Eigen::Vector2d> pts;
    pts.reserve(trace.dL.size());
    for (size_t i = 0; i < trace.dL.size(); ++i) {
        const double a = trace.angleDeg[i] * kDeg, r = run.LB + trace.dL[i];
        pts.emplace_back(r * std::cos(a), r * std::sin(a));
    }
    const CircleFit f = fitCircle(pts);
    const RunPlane p = runPlane(m, run);
    Vec3 e = f.center.x() * p.u + f.center.y() * p.v;
    e[p.normalIndex] = std::numeric_limits<double>::quiet_NaN();
    return e;
}

}  // namespace cnccomp
