#include "cnccomp/identification/rtest_axis_tables.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>

#include <Eigen/QR>
#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/identification/identifiability.hpp"
#include "cnccomp/identification/levenberg_marquardt.hpp"
#include "cnccomp/identification/problem.hpp"
#include "cnccomp/identification/rtest_observation.hpp"

namespace cnccomp::identification {
using namespace cnccomp::measurement;

namespace {


/// Nominal pose (bed frame) of a workpiece-side axis' frame after its motion.
Pose nominalAxisFrame(const MachineModel& m, int axis, const AxisVector& q) {
    Pose p = Pose::Identity();
    for (const Link& l : m.workpiece.links) {
        p = p * l.placement;
        if (l.kind == AxisKind::Linear) p.translation() += p.linear() * (l.direction * q[l.axisIndex]);
        if (l.kind == AxisKind::Rotary) p.linear() = p.linear() * axisRotation(l.direction, q[l.axisIndex]);
        if (l.axisIndex == axis) return p;
    }
    throw ModelError(fmt::format("machine '{}': axis {} is not on the workpiece side", m.name, m.axisNames[static_cast<size_t>(axis)]));
}

int requireWorkpieceRotary(const MachineModel& m, const std::string& axis) {
    const int a = m.requireAxis(axis);
    if (m.axisSide(a) != Side::Workpiece || m.axisLink(a).kind != AxisKind::Rotary)
        throw ModelError(fmt::format("machine '{}': axis '{}' must be a rotary axis of the workpiece (table) side", m.name, axis));
    return a;
}

constexpr const char* kComponents[] = {"EX", "EY", "EZ", "EA", "EB", "EC"};

std::array<const DeviationDef*, 6> axisTables(const MachineModel& m, const std::string& axis) {
    std::array<const DeviationDef*, 6> t{};
    for (int c = 0; c < 6; ++c) {
        const std::string name = kComponents[c] + axis;
        const int i = m.deviationIndex(name);
        if (i < 0) throw ModelError(fmt::format("machine '{}' has no component error '{}' (the per-angle R-test method needs all six of {})", m.name, name, axis));
        const DeviationDef& d = m.deviations[static_cast<size_t>(i)];
        if (d.kind != DeviationKind::Component || d.basis.type != ComponentBasis::Type::Table)
            throw ModelError(fmt::format("machine '{}': '{}' must be a component error with a table basis", m.name, name));
        if (c > 0 && d.basis.nodes != t[0]->basis.nodes)
            throw ModelError(fmt::format("machine '{}': the six tables of axis {} must share their nodes", m.name, axis));
        t[static_cast<size_t>(c)] = &d;
    }
    return t;
}

double normalizedDeg(double deg, bool modulo) {
    if (!modulo) return deg;
    double a = std::fmod(deg, 360.0);
    if (a < 0) a += 360.0;
    return a >= 360.0 - 1e-9 ? 0.0 : a;
}

Vec3 rotationLog(const Mat3& r) {
    const Eigen::AngleAxisd aa(r);
    return aa.angle() * aa.axis();
}

Vec6 poseToErrors(const Pose& p) {
    Vec6 e;
    e.head<3>() = p.translation();
    e.tail<3>() = rotationLog(p.linear());
    return e;
}

}  // namespace

AxisErrors cradleAxisErrors(const MachineModel& m, const std::string& axis, const std::vector<RtestRun>& runs,
                            const std::vector<RtestTrace>& traces) {
    if (runs.size() != traces.size()) throw ModelError(fmt::format("{} R-test runs but {} traces", runs.size(), traces.size()));
    const int ax = requireWorkpieceRotary(m, axis);
    const bool modulo = m.axisLink(ax).modulo;
    const Kinematics nominal(m);
    struct Row {
        Vec3 p, d;
    };
    std::map<long long, std::vector<Row>> rows;
    std::map<long long, double> angleOf;
    for (size_t r = 0; r < runs.size(); ++r) {
        const RtestRun& run = runs[r];
        int s = -1;
        bool othersStill = true;
        for (size_t k = 0; k < run.sweeps.size(); ++k) {
            const bool moves = run.sweeps[k].startDeg != run.sweeps[k].endDeg;
            if (run.sweeps[k].axis == axis && moves) s = static_cast<int>(k);
            else if (moves) othersStill = false;
        }
        if (s < 0 || !othersStill) continue;
        const RtestTrace& t = traces[r];
        if (t.commands.size() != t.d.size()) throw ModelError(fmt::format("R-test run '{}': poses and displacements differ", run.name));
        const Vec3 nest = nominal.toolPoint(run.nestLength);
        const Vec3 ball = run.ball + run.ballOffset;
        for (size_t i = 0; i < t.d.size(); ++i) {
            const AxisVector& q = t.commands[i];
            const double deg = normalizedDeg(q[ax] / kDeg, modulo);
            const Pose F = nominalAxisFrame(m, ax, q);
            const Vec3 bNominal = nominal.baseToWorkpiece(q) * ball;
            const Vec3 bActual = nominal.baseToTool(q) * (nest + t.d[i]);
            const long long key = std::llround(deg * 1e6);
            rows[key].push_back({F.inverse(Eigen::Isometry) * bNominal, F.linear().transpose() * (bActual - bNominal)});
            angleOf[key] = deg;
        }
    }
    if (rows.empty()) throw ModelError(fmt::format("no R-test run turns axis {} alone", axis));
    AxisErrors out;
    out.axis = axis;
    for (const auto& [key, list] : rows) {
        const Eigen::Index n = static_cast<Eigen::Index>(list.size());
        Eigen::MatrixXd A(3 * n, 6);
        Eigen::VectorXd b(3 * n);
        for (Eigen::Index k = 0; k < n; ++k) {
            A.block(3 * k, 0, 3, 3) = Mat3::Identity();
            A.block(3 * k, 3, 3, 3) = -skew(list[static_cast<size_t>(k)].p);  // ξ × p = −[p]× ξ
            b.segment<3>(3 * k) = list[static_cast<size_t>(k)].d;
        }
        Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(A);
        qr.setThreshold(1e-9);
        if (qr.rank() < 6)
            throw ModelError(fmt::format("axis {} at {:g} deg: {} ball position(s) do not fix the six errors (need three "
                                         "non-collinear balls)", axis, angleOf[key], n));
        const Eigen::VectorXd x = qr.solve(b);
        AxisErrorSample s;
        s.angleDeg = angleOf[key];
        s.delta = x.head<3>();
        s.xi = x.tail<3>();
        s.balls = static_cast<int>(n);
        s.rms = std::sqrt((A * x - b).squaredNorm() / static_cast<double>(3 * n));
        out.samples.push_back(s);
    }
    std::sort(out.samples.begin(), out.samples.end(), [](const auto& a, const auto& b) { return a.angleDeg < b.angleDeg; });
    return out;
}

DeviationSet cradleDeviations(const MachineModel& m, const std::vector<AxisErrors>& errors) {
    DeviationSet set(m);
    for (const AxisErrors& e : errors) {
        const int ax = requireWorkpieceRotary(m, e.axis);
        const bool modulo = m.axisLink(ax).modulo;
        const auto tables = axisTables(m, e.axis);
        const auto& s = e.samples;
        if (s.empty()) throw ModelError(fmt::format("axis {}: no samples", e.axis));
        for (int k = 0; k < tables[0]->size(); ++k) {
            double t = tables[0]->basis.nodes[static_cast<size_t>(k)] / kDeg;
            if (modulo) {
                t = s.front().angleDeg + std::fmod(t - s.front().angleDeg, 360.0);
                if (t < s.front().angleDeg) t += 360.0;
            }
            size_t hi = 0;
            while (hi < s.size() && s[hi].angleDeg < t - 1e-9) ++hi;
            const AxisErrorSample* a = nullptr;
            const AxisErrorSample* b = nullptr;
            double ta = 0, tb = 0;
            if (hi < s.size() && std::abs(s[hi].angleDeg - t) <= 1e-9) {
                a = b = &s[hi];
            } else if (hi > 0 && hi < s.size()) {
                a = &s[hi - 1];
                b = &s[hi];
                ta = a->angleDeg;
                tb = b->angleDeg;
            } else if (modulo && hi == s.size()) {
                a = &s.back();
                b = &s.front();
                ta = a->angleDeg;
                tb = b->angleDeg + 360.0;
            } else {
                throw ModelError(fmt::format("table node {:g} deg of axis {} lies outside the measured angles",
                                             tables[0]->basis.nodes[static_cast<size_t>(k)] / kDeg, e.axis));
            }
            const double f = a == b ? 0.0 : (t - ta) / (tb - ta);
            for (int c = 0; c < 6; ++c) {
                const double va = c < 3 ? a->delta[c] : a->xi[c - 3];
                const double vb = c < 3 ? b->delta[c] : b->xi[c - 3];
                set.values[tables[static_cast<size_t>(c)]->offset + k] = va + f * (vb - va);
            }
        }
        for (int c = 0; c < 6; ++c) set.present[static_cast<size_t>(m.deviationIndex(tables[static_cast<size_t>(c)]->name))] = 1;
    }
    return set;
}

DeviationSet cradleTablesPerAngle(const MachineModel& m, const std::string& outerAxis, const std::string& innerAxis,
                             const std::vector<RtestRun>& runs, const std::vector<RtestTrace>& traces,
                             std::vector<AxisErrors>* perAngle) {
    const AxisErrors outer = cradleAxisErrors(m, outerAxis, runs, traces);
    const DeviationSet outerSet = cradleDeviations(m, {outer});
    const Kinematics withOuter(m, outerSet), nominal(m);
    std::vector<RtestTrace> corrected = traces;
    for (size_t r = 0; r < runs.size(); ++r) {
        const RtestTrace p = simulateRtest(withOuter, runs[r], traces[r].commands);
        const RtestTrace z = simulateRtest(nominal, runs[r], traces[r].commands);
        for (size_t i = 0; i < p.d.size(); ++i) corrected[r].d[i] -= p.d[i] - z.d[i];
    }
    const AxisErrors inner = cradleAxisErrors(m, innerAxis, runs, corrected);
    if (perAngle) *perAngle = {outer, inner};
    return cradleDeviations(m, {outer, inner});
}

Vec3 cradleSmallAngle(const Vec3& outerAxis, double alpha, const SixErrors& outer, const Vec3& innerAxis, double gamma,
                      const SixErrors& inner, const Vec3& w) {
    const Vec3 cW = inner.delta + (Mat3::Identity() + skew(inner.xi)) * w;                                // (1), (3)
    const Vec3 aW = outer.delta + (Mat3::Identity() + skew(outer.xi)) * (axisRotation(innerAxis, gamma) * cW);  // (4), (5), (6)
    return axisRotation(outerAxis, alpha) * aW;                                                          // (7)
}

CradleLsq cradleLeastSquares(const MachineModel& m, const std::string& outerAxis, const std::string& innerAxis,
                             const std::vector<RtestRun>& runs, const std::vector<RtestTrace>& traces,
                             const IdentifyOptions& options) {
    const int ao = requireWorkpieceRotary(m, outerAxis), ai = requireWorkpieceRotary(m, innerAxis);
    const auto tO = axisTables(m, outerAxis), tI = axisTables(m, innerAxis);
    int lo = -1, li = -1;
    for (int i = 0; i < static_cast<int>(m.workpiece.links.size()); ++i) {
        if (m.workpiece.links[static_cast<size_t>(i)].axisIndex == ao) lo = i;
        if (m.workpiece.links[static_cast<size_t>(i)].axisIndex == ai) li = i;
    }
    if (li != lo + 1)
        throw ModelError(fmt::format("machine '{}': axis {} must follow axis {} directly in the workpiece chain", m.name,
                                     innerAxis, outerAxis));
    const Observations obs = rtestObservations(m, runs, traces);
    std::vector<int> devs;
    for (const auto* d : tO) devs.push_back(m.deviationIndex(d->name));
    for (const auto* d : tI) devs.push_back(m.deviationIndex(d->name));
    std::sort(devs.begin(), devs.end());
    const DeviationSet start = options.start ? *options.start : DeviationSet(m);
    const UnknownLayout layout(m, devs, obs);
    const LsqProblem problem(m, obs, layout, start);
    SolverSettings s;
    s.maxIterations = options.maxIterations;
    s.rankTolerance = options.rankTolerance;
    const Eigen::VectorXd x0 = problem.start();
    const ObservableSubspace sub = observableSubspace(problem, options.rankTolerance);
    const SolverOutcome so = levenbergMarquardt(problem, x0, s, &sub.basis);
    CradleLsq out{IdentificationReport{}, problem.deviations(so.x)};
    IdentificationReport& rep = out.report;
    rep.machine = m.name;
    rep.method = "least-squares (six error tables per rotary axis, gauge: inner-axis errors zero at 0)";
    rep.solver = "levenberg-marquardt";
    rep.termination = so.termination;
    rep.converged = so.converged;
    rep.iterations = so.iterations;
    rep.evaluations = so.evaluations;
    analyzeSolution(problem, sub, x0, so.x, options.rankTolerance, rep);

    // Gauge: bMw = … Rot_o(a)·E_o(a)·P·Rot_i(c)·E_i(c); with G = E_i(0) and T = P·G·P⁻¹ the same machine is
    // E_o'(a) = E_o(a)·T, E_i'(c) = Rot_i(c)ᵀ·G⁻¹·Rot_i(c)·E_i(c), and E_i'(0) = I.
    DeviationSet& d = out.deviations;
    const Link& inner = m.workpiece.links[static_cast<size_t>(li)];
    Vec6 loc = Vec6::Zero();
    for (const DeviationDef& def : m.deviations)
        if (def.side == Side::Workpiece && def.link == li && def.kind == DeviationKind::Location)
            loc[def.component] += d.values[def.offset];
    const Pose P = inner.placement * errorTransform(loc);
    const auto errorsAt = [&](const std::array<const DeviationDef*, 6>& t, double q, bool modulo) {
        Vec6 e;
        for (int c = 0; c < 6; ++c) e[c] = t[static_cast<size_t>(c)]->basis.evaluate(q, d.values.data() + t[static_cast<size_t>(c)]->offset, modulo);
        return errorTransform(e);
    };
    const Pose G = errorsAt(tI, 0.0, inner.modulo);
    const Pose T = P * G * P.inverse(Eigen::Isometry);
    const Pose Ginv = G.inverse(Eigen::Isometry);
    const bool outerModulo = m.axisLink(ao).modulo;
    for (int k = 0; k < tO[0]->size(); ++k) {
        const Vec6 e = poseToErrors(errorsAt(tO, tO[0]->basis.nodes[static_cast<size_t>(k)], outerModulo) * T);
        for (int c = 0; c < 6; ++c) d.values[tO[static_cast<size_t>(c)]->offset + k] = e[c];
    }
    std::vector<Vec6> innerNew;
    for (int k = 0; k < tI[0]->size(); ++k) {
        const double c = tI[0]->basis.nodes[static_cast<size_t>(k)];
        Pose rot = Pose::Identity();
        rot.linear() = axisRotation(inner.direction, c);
        innerNew.push_back(poseToErrors(rot.inverse(Eigen::Isometry) * Ginv * rot * errorsAt(tI, c, inner.modulo)));
    }
    for (int k = 0; k < tI[0]->size(); ++k)
        for (int c = 0; c < 6; ++c) d.values[tI[static_cast<size_t>(c)]->offset + k] = innerNew[static_cast<size_t>(k)][c];
    for (int i : devs) d.present[static_cast<size_t>(i)] = 1;
    return out;
}

}  // namespace cnccomp::identification
