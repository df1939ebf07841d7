#include "cnccomp/identification/dbb5_cone_frustum.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/identification/dbb5_observation.hpp"

namespace cnccomp::identification {
using namespace cnccomp::measurement;

namespace {

Vec3 onCone(const Dbb5Run& run, double phiDeg, double radial, double axial) {
    const double phi = phiDeg * kDeg;
    return Eigen::AngleAxisd(run.coneTiltDeg * kDeg, Vec3::UnitY()) *
           Vec3(radial * std::cos(phi), radial * std::sin(phi), axial);
}

/// The tilting table's two rotary links and the nominal rotations around them: bMw = A0·R1(q1)·A1·R2(q2)·A2.
struct TableChain {
    int axis1 = -1, axis2 = -1;
    Vec3 w1, w2;
    Mat3 A0 = Mat3::Identity(), A1 = Mat3::Identity(), A2 = Mat3::Identity();
    Vec3 toolAxisBed;  ///< tip → spindle, bed frame (the tool side only translates)
};

TableChain tableChain(const MachineModel& m) {
    TableChain c;
    int stage = 0;
    Mat3* A[3] = {&c.A0, &c.A1, &c.A2};
    for (const Link& l : m.workpiece.links) {
        if (stage > 2) break;
        *A[stage] = *A[stage] * l.placement.linear();
        if (l.kind != AxisKind::Rotary) continue;
        if (stage == 2) stage = 3;  // a third rotary axis
        else {
            (stage == 0 ? c.axis1 : c.axis2) = l.axisIndex;
            (stage == 0 ? c.w1 : c.w2) = l.direction.normalized();
            ++stage;
        }
    }
    bool toolRotary = false;
    Mat3 T = Mat3::Identity();
    for (const Link& l : m.tool.links) {
        T = T * l.placement.linear();
        toolRotary = toolRotary || l.kind == AxisKind::Rotary;
    }
    if (stage != 2 || toolRotary)
        throw ModelError(fmt::format("machine '{}': the cone-frustum run needs a tilting rotary table (two rotary axes on "
                                     "the workpiece side, none on the tool side)",
                                     m.name));
    c.toolAxisBed = -(T * m.toolDirection).normalized();
    return c;
}

/// Both outer angles keeping the inner axis' share of the tool direction (Paden–Kahan subproblem 4).
std::pair<double, double> outerAngles(const TableChain& c, const Vec3& a, const Vec3& w2, const Vec3& b,
                                      const MachineModel& m) {
    const double k = w2.dot(a);
    const double alpha = c.w1.dot(w2) * c.w1.dot(b);
    const double beta = (w2 - c.w1 * c.w1.dot(w2)).dot(b);
    const double gamma = c.w1.cross(w2).dot(b);
    const double rho = std::hypot(beta, gamma);
    if (rho < 1e-12) return {0.0, 0.0};  // the inner axis' share does not change with the outer angle
    if (std::abs(k - alpha) > rho * (1 + 1e-9))
        throw ModelError(fmt::format("machine '{}': the table cannot turn the tool to this direction", m.name));
    const double delta = std::atan2(gamma, beta);
    const double acosine = std::acos(std::clamp((k - alpha) / rho, -1.0, 1.0));
    return {std::remainder(delta + acosine, 2 * kPi), std::remainder(delta - acosine, 2 * kPi)};
}

}  // namespace

Vec3 dbb5ConeToolAxis(const Dbb5Run& run, double phiDeg) {
    const double t = run.toolAngleDeg * kDeg;
    return onCone(run, phiDeg, -std::sin(t), std::cos(t));
}

Vec3 dbb5ConeBarDirection(const Dbb5Run& run, double phiDeg) {
    const double z = run.barAngleDeg * kDeg;
    return onCone(run, phiDeg, std::sin(z), std::cos(z));
}

AxisVector dbb5TableOrientation(const MachineModel& m, const Vec3& toolAxisW, int branch, AxisVector q) {
    const TableChain c = tableChain(m);
    // A0·R1·A1·R2·A2·t = v  ⇔  R2'(q2)·a = R1(−q1)·b with R2' about w2 = A1·w2, a = A1·A2·t, b = A0ᵀ·v.
    const Vec3 w2 = (c.A1 * c.w2).normalized();
    const Vec3 a = c.A1 * c.A2 * toolAxisW.normalized();
    const Vec3 b = c.A0.transpose() * c.toolAxisBed;
    const auto [plus, minus] = outerAngles(c, a, w2, b, m);
    const double q1 = branch >= 0 ? plus : minus;
    // Inner angle: turn a onto R1(−q1)·b about w2 (Paden–Kahan subproblem 1).
    const Vec3 target = axisRotation(c.w1, -q1) * b;
    const Vec3 ap = a - w2 * w2.dot(a), tp = target - w2 * w2.dot(target);
    const double q2 = ap.norm() < 1e-12 || tp.norm() < 1e-12 ? 0.0 : std::atan2(w2.dot(ap.cross(tp)), ap.dot(tp));
    q[c.axis1] = q1;
    q[c.axis2] = q2;
    return q;
}

int dbb5ConeBranch(const MachineModel& m, const Dbb5Run& run) {
    const AxisVector zero = AxisVector::Zero(m.axisCount());
    const int axis1 = tableChain(m).axis1;
    const Vec3 t = dbb5ConeToolAxis(run, run.setupDeg);
    const double plus = dbb5TableOrientation(m, t, +1, zero)[axis1], minus = dbb5TableOrientation(m, t, -1, zero)[axis1];
    return std::abs(minus) < std::abs(plus) - 1e-12 ? -1 : +1;
}

Dbb5ConeEvaluation evaluateDbb5ConeRun(const MachineModel& m, const Dbb5Run& run, const BallbarTrace& trace,
                                       const DeviationSet* deviations) {
    if (run.kind != Dbb5Run::Kind::ConeFrustum)
        throw ModelError(fmt::format("DBB5 run '{}' is not a cone-frustum run", run.name));
    Dbb5ConeEvaluation e;
    e.run = run.name;
    e.iso = evaluateCircularTest(trace, run.LB);
    if (!deviations) return e;
    const Dbb5Observation obs(m, run, trace);
    BallbarTrace p;
    p.angleDeg = trace.angleDeg;
    p.dL.resize(trace.dL.size());
    obs.predict(Kinematics(m, *deviations), nullptr, p.dL.data());
    double sum = 0;
    for (size_t i = 0; i < p.dL.size(); ++i) {
        const double d = trace.dL[i] - p.dL[i];
        sum += d * d;
        e.maxDifference = std::max(e.maxDifference, std::abs(d));
    }
    e.rmsDifference = std::sqrt(sum / static_cast<double>(p.dL.size()));
    e.predicted = std::move(p);
    return e;
}

}  // namespace cnccomp::identification
