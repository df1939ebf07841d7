#include "cnccomp/identification/tilting_head_errors.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/identification/absolute_ballbar_observation.hpp"

namespace cnccomp::identification {

BallbarTrace simulateAbsoluteRun(const Kinematics& k, const BallbarRun& run) {
    const MachineModel& m = k.machine();
    const Kinematics nominal(m);
    const std::vector<double> angles = run.anglesDeg();
    const AxisVector setup = setupCommands(m, run);
    const Vec3 wBall =
        nominal.toolPointInWorkpiece(setup, nominal.toolPoint(run.RB, run.toolBallOffset)) + run.workBallOffset;
    const Vec3 tBall = k.toolPoint(run.RB, run.toolBallOffset);
    BallbarTrace t;
    t.angleDeg = angles;
    t.dL.resize(angles.size());
    for (size_t i = 0; i < angles.size(); ++i) {
        const AxisVector q = runCommands(m, run, angles[i] * kDeg);
        try {
            k.checkTravel(q);
        } catch (const ModelError& e) {
            throw ModelError(fmt::format("run '{}' at {:g} deg: {}", run.name, angles[i], e.what()));
        }
        t.dL[i] = (k.toolPointInWorkpiece(q, tBall) - wBall).norm() - run.LB;
    }
    return t;
}

namespace {

enum Pattern { kX = 0, kY = 1, kZ = 2 };

struct PatternRuns {
    std::array<const BallbarRun*, 2> run{nullptr, nullptr};   ///< [0] shorter tool, [1] longer
    std::array<const BallbarTrace*, 2> trace{nullptr, nullptr};
};

std::array<PatternRuns, 3> selectPatterns(const std::vector<BallbarRun>& runs, const std::vector<BallbarTrace>& traces) {
    if (runs.size() != traces.size()) throw ModelError(fmt::format("{} runs but {} traces", runs.size(), traces.size()));
    std::array<std::vector<size_t>, 3> found;
    for (size_t i = 0; i < runs.size(); ++i) {
        if (runs[i].test == BallbarTest::BX) found[kX].push_back(i);
        if (runs[i].test == BallbarTest::BY) found[kY].push_back(i);
        if (runs[i].test == BallbarTest::BZ) found[kZ].push_back(i);
    }
    static constexpr const char* names[] = {"B-X (X pattern)", "B-Y (Y pattern)", "B-Z (Z pattern)"};
    std::array<PatternRuns, 3> out;
    for (int p = 0; p < 3; ++p) {
        if (found[p].size() != 2)
            throw ModelError(fmt::format("the head patterns need two {} runs with different tool lengths RB; the plan has {}",
                                         names[p], found[p].size()));
        size_t a = found[p][0], b = found[p][1];
        if (runs[a].RB > runs[b].RB) std::swap(a, b);
        if (!(runs[b].RB - runs[a].RB > 1e-6))
            throw ModelError(fmt::format("the two {} runs '{}' and '{}' need different tool lengths RB", names[p],
                                         runs[a].name, runs[b].name));
        if (runs[a].headAxis != runs[0].headAxis || runs[b].headAxis != runs[0].headAxis)
            throw ModelError("head patterns: every pattern must turn the same head axis");
        out[p].run = {&runs[a], &runs[b]};
        out[p].trace = {&traces[a], &traces[b]};
    }
    return out;
}

/// Index of `deg` in a trace, or -1.
int findAngle(const BallbarTrace& t, double deg) {
    for (size_t i = 0; i < t.angleDeg.size(); ++i)
        if (std::abs(std::remainder(t.angleDeg[i] - deg, 360.0)) < 1e-6) return static_cast<int>(i);
    return -1;
}

}  // namespace

TiltingHeadResult tiltingHeadFormulas(const std::vector<BallbarRun>& runs, const std::vector<BallbarTrace>& traces) {
    const auto pat = selectPatterns(runs, traces);
    TiltingHeadResult r;
    r.headAxis = pat[kY].run[0]->headAxis;
    r.L1 = pat[kY].run[0]->RB;
    r.L2 = pat[kY].run[1]->RB;
    // Common sample angles of the six runs.
    std::vector<std::array<int, 6>> rows;
    std::vector<double> angles;
    for (size_t i = 0; i < pat[kY].trace[0]->angleDeg.size(); ++i) {
        const double a = pat[kY].trace[0]->angleDeg[i];
        std::array<int, 6> idx{};
        bool all = true;
        for (int p = 0; p < 3 && all; ++p)
            for (int l = 0; l < 2 && all; ++l) {
                const BallbarTrace& t = *pat[p].trace[l];
                if (t.angleDeg.size() != t.dL.size()) throw ModelError("head patterns: a trace has mismatched columns");
                idx[p * 2 + l] = findAngle(t, a);
                all = idx[p * 2 + l] >= 0;
            }
        if (all) {
            rows.push_back(idx);
            angles.push_back(a);
        }
    }
    if (rows.empty()) throw ModelError("head patterns: the six runs share no sample angle");
    const auto delta = [&](int p, int l, size_t row) { return pat[p].trace[l]->dL[static_cast<size_t>(rows[row][p * 2 + l])]; };
    // Eq. (7): Q_j and δy(B_j) from the Y pattern.
    const double Ly1 = pat[kY].run[0]->RB, Ly2 = pat[kY].run[1]->RB;
    std::vector<double> Q(rows.size());
    for (size_t j = 0; j < rows.size(); ++j) Q[j] = (delta(kY, 1, j) - delta(kY, 0, j)) / (Ly2 - Ly1);
    // Eq. (9): εBz = Q(0), εxB = (Q(270°) − Q(90°))/2.
    const auto at = [&](double deg) -> int {
        for (size_t j = 0; j < angles.size(); ++j)
            if (std::abs(std::remainder(angles[j] - deg, 360.0)) < 1e-6) return static_cast<int>(j);
        throw ModelError(fmt::format("the head-pattern formula (9) needs a common sample at B = {:g} deg", deg));
    };
    r.eBz = Q[static_cast<size_t>(at(0))];
    r.exB = (Q[static_cast<size_t>(at(270))] - Q[static_cast<size_t>(at(90))]) / 2;
    const double Lx1 = pat[kX].run[0]->RB, Lx2 = pat[kX].run[1]->RB;
    const double Lz1 = pat[kZ].run[0]->RB, Lz2 = pat[kZ].run[1]->RB;
    std::vector<size_t> order(rows.size());
    for (size_t j = 0; j < order.size(); ++j) order[j] = j;
    std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return angles[a] < angles[b]; });
    for (size_t j : order) {
        TiltingHeadAngle h;
        h.angleDeg = angles[j];
        const double B = angles[j] * kDeg, c = std::cos(B), s = std::sin(B);
        h.Q = Q[j];
        h.dy = (Ly2 * delta(kY, 0, j) - Ly1 * delta(kY, 1, j)) / (Ly2 - Ly1);  // (7)
        h.ex = Q[j] - r.eBz * c + r.exB * s;                                     // (9)
        h.P = (Lx2 * delta(kX, 0, j) - Lx1 * delta(kX, 1, j)) / (Lx2 - Lx1);   // (16)
        if (std::abs(c) >= 0.5) {
            h.ey = -(delta(kX, 1, j) - delta(kX, 0, j)) / ((Lx2 - Lx1) * c);   // (16), sign from (15)
        } else {
            h.ey = (delta(kZ, 1, j) - delta(kZ, 0, j)) / ((Lz2 - Lz1) * s);    // (20) with two tool lengths
            h.eyFromZ = true;
        }
        h.R = delta(kZ, 0, j) - Lz1 * s * h.ey;                                 // (20)
        h.dz = c * h.R + s * h.P;                                                // (21)
        h.dx = c * h.P - s * h.R;                                                // (21)
        r.angles.push_back(h);
    }
    return r;
}

namespace {

const DeviationDef& requireTable(const MachineModel& m, const std::string& name) {
    const int i = m.deviationIndex(name);
    if (i < 0) throw ModelError(fmt::format("machine '{}' has no deviation '{}' (the head-pattern method identifies it)", m.name, name));
    const DeviationDef& d = m.deviations[static_cast<size_t>(i)];
    if (d.kind != DeviationKind::Component || d.basis.type != ComponentBasis::Type::Table)
        throw ModelError(fmt::format("machine '{}': '{}' must be a component error with a table basis", m.name, name));
    return d;
}

std::array<std::string, 5> tableNames(const std::string& head) {
    return {"EX" + head, "EY" + head, "EZ" + head, "EA" + head, "EB" + head};
}

}  // namespace

DeviationSet tiltingHeadDeviations(const MachineModel& m, const TiltingHeadResult& r) {
    DeviationSet set(m);
    // εxB, εBz are the orientation errors of the head's own link (the paper's matrix), i.e. link values.
    set.setLinkValue("EC0" + r.headAxis, r.exB);
    set.setLinkValue("EA0" + r.headAxis, r.eBz);
    const auto names = tableNames(r.headAxis);
    for (int c = 0; c < 5; ++c) {
        const DeviationDef& d = requireTable(m, names[static_cast<size_t>(c)]);
        for (int k = 0; k < d.size(); ++k) {
            const double node = d.basis.nodes[static_cast<size_t>(k)] / kDeg;
            size_t hi = 0;
            while (hi < r.angles.size() && r.angles[hi].angleDeg < node - 1e-9) ++hi;
            if (hi == r.angles.size() || (r.angles[hi].angleDeg > node + 1e-9 && hi == 0))
                throw ModelError(fmt::format("table node {:g} deg of '{}' lies outside the measured angles", node, d.name));
            const auto value = [&](const TiltingHeadAngle& h) {
                const double v[] = {h.dx, h.dy, h.dz, h.ex, h.ey};
                return v[c];
            };
            double v = value(r.angles[hi]);
            if (r.angles[hi].angleDeg > node + 1e-9) {
                const TiltingHeadAngle& a = r.angles[hi - 1];
                const TiltingHeadAngle& b = r.angles[hi];
                v = value(a) + (value(b) - value(a)) * (node - a.angleDeg) / (b.angleDeg - a.angleDeg);
            }
            set.values[d.offset + k] = v;
        }
        set.present[static_cast<size_t>(m.deviationIndex(d.name))] = 1;
    }
    return set;
}

TiltingHeadLsq tiltingHeadLeastSquares(const MachineModel& m, const std::vector<BallbarRun>& runs,
                                       const std::vector<BallbarTrace>& traces, const IdentifyOptions& options) {
    const auto pat = selectPatterns(runs, traces);  // checks the plan has the six runs
    const std::string head = pat[kY].run[0]->headAxis;
    std::vector<BallbarRun> use;
    std::vector<BallbarTrace> useTraces;
    for (int p = 0; p < 3; ++p)
        for (int l = 0; l < 2; ++l) {
            use.push_back(*pat[p].run[l]);
            useTraces.push_back(*pat[p].trace[l]);
        }
    const Observations obs = absoluteBallbarObservations(m, use, useTraces);
    const auto names = tableNames(head);
    std::array<const DeviationDef*, 5> defs{};
    IdentifyOptions o = options;
    o.deviations.clear();
    for (int c = 0; c < 5; ++c) {
        defs[static_cast<size_t>(c)] = &requireTable(m, names[static_cast<size_t>(c)]);
        o.deviations.push_back(m.deviationIndex(names[static_cast<size_t>(c)]));
        if (defs[static_cast<size_t>(c)]->basis.nodes != defs[0]->basis.nodes)
            throw ModelError(fmt::format("machine '{}': the tables {} .. {} must share their nodes", m.name, names[0], names[4]));
    }
    TiltingHeadLsq out{identify(m, obs, o), DeviationSet(m)};
    // Gauge split (eq. (9)) by an exact change of frame: the head frame after the motion is R(w)·Rot(B); the
    // engine's solution (w_ls, tables) and the paper's (w', tables') must put every tool point at the same place:
    //   δ' = M δ,  R(ε')·u = M R(ε)·u,  M = Rot(B)ᵀ R(w')ᵀ R(w_ls) Rot(B), u the spindle direction, ε' ⟂ u.
    const DeviationSet& ls = out.engine.deviations;
    const int axis = m.requireAxis(head);
    const Link& link = m.axisLink(axis);
    const DeviationDef& ex = *defs[3];
    const Vec3 wls(ls.linkValue("EA0" + head), ls.linkValue("EB0" + head), ls.linkValue("EC0" + head));
    const Vec3 u = m.toolDirection;
    const int ecIndex = m.deviationIndex("EC" + head);
    const auto exAt = [&](const DeviationSet& s, double deg) {
        return ex.basis.evaluate(deg * kDeg, s.values.data() + ex.offset, link.modulo);
    };
    const auto split = [&](double alpha, double gamma) {
        DeviationSet d = ls;
        const Vec3 w(alpha, wls.y(), gamma);
        for (int k = 0; k < ex.size(); ++k) {
            const double B = ex.basis.nodes[static_cast<size_t>(k)];
            const Mat3 rot = axisRotation(link.direction, B);
            const Mat3 M = rot.transpose() * rotationVector(w).transpose() * rotationVector(wls) * rot;
            Vec3 delta, eps;
            for (int c = 0; c < 3; ++c) delta[c] = ls.values[defs[static_cast<size_t>(c)]->offset + k];
            const double ez = ecIndex < 0 ? 0.0
                                          : m.deviations[static_cast<size_t>(ecIndex)].basis.evaluate(
                                                B, ls.values.data() + m.deviations[static_cast<size_t>(ecIndex)].offset, link.modulo);
            eps << ls.values[defs[3]->offset + k], ls.values[defs[4]->offset + k], ez;
            const Vec3 dNew = M * delta;
            const Vec3 t = M * rotationVector(eps) * u;
            const Vec3 axisVec = u.cross(t);
            const double angle = std::atan2(axisVec.norm(), u.dot(t));
            const Vec3 eNew = axisVec.norm() > 0 ? Vec3(angle * axisVec / axisVec.norm()) : Vec3::Zero();
            for (int c = 0; c < 3; ++c) d.values[defs[static_cast<size_t>(c)]->offset + k] = dNew[c];
            d.values[defs[3]->offset + k] = eNew.x();
            d.values[defs[4]->offset + k] = eNew.y();
        }
        d.setLinkValue("EA0" + head, alpha);
        d.setLinkValue("EC0" + head, gamma);
        return d;
    };
    // First-order gauge from Q(B) = εBz cos B − εxB sin B + εx(B), then Newton on the exact gauge conditions
    // εx(0) = 0 and εx(90°) = εx(−90°) of the split tables.
    const auto Q = [&](double deg) {
        const double B = deg * kDeg;
        return wls.x() * std::cos(B) - wls.z() * std::sin(B) + exAt(ls, deg);
    };
    double alpha = Q(0), gamma = (Q(-90) - Q(90)) / 2;
    for (int it = 0; it < 4; ++it) {
        const DeviationSet d = split(alpha, gamma);
        alpha += exAt(d, 0);
        gamma -= (exAt(d, 90) - exAt(d, -90)) / 2;
    }
    out.deviations = split(alpha, gamma);
    return out;
}

}  // namespace cnccomp::identification
