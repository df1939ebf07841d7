#include "cnccomp/identification/planner.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/QR>
#include <Eigen/SVD>
#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/identification/eccentricity_observation.hpp"
#include "cnccomp/identification/observation.hpp"
#include "cnccomp/identification/parameters.hpp"
#include "cnccomp/identification/problem.hpp"

namespace cnccomp::identification {

namespace {

struct Candidate {
    BallbarRun run;
    Eigen::MatrixXd R;  ///< R factor of the nuisance-free scaled Jacobian over every flat deviation (N × N)
};

/// Rank, Σ log sᵢ over the rank, condition number and pseudo-inverse diagonal of a stacked set of R blocks,
/// restricted to columns `cols`.
struct SetScore {
    int rank = 0;
    double logDet = -std::numeric_limits<double>::infinity();
    double condition = std::numeric_limits<double>::infinity();
    Eigen::MatrixXd nullProjector;  ///< over cols
    Eigen::VectorXd variance;       ///< diag of the pseudo-inverse information, solver units² per (mm of noise)²
};

SetScore score(const std::vector<const Candidate*>& set, const std::vector<int>& cols, double rankTol) {
    const int n = static_cast<int>(cols.size());
    SetScore s;
    if (set.empty()) {
        s.nullProjector = Eigen::MatrixXd::Identity(n, n);
        s.variance = Eigen::VectorXd::Constant(n, std::numeric_limits<double>::infinity());
        return s;
    }
    Eigen::MatrixXd stacked(static_cast<Eigen::Index>(set.size()) * set[0]->R.rows(), n);
    Eigen::Index row = 0;
    for (const Candidate* c : set) {
        for (int j = 0; j < n; ++j) stacked.block(row, j, c->R.rows(), 1) = c->R.col(cols[j]);
        row += c->R.rows();
    }
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(stacked, Eigen::ComputeFullV);
    const Eigen::VectorXd& sv = svd.singularValues();
    const double smax = sv.size() ? sv[0] : 0.0;
    s.logDet = 0;
    for (Eigen::Index i = 0; i < sv.size(); ++i)
        if (sv[i] > rankTol * smax && sv[i] > 0) {
            ++s.rank;
            s.logDet += std::log(sv[i]);
        }
    s.condition = s.rank > 0 ? smax / sv[s.rank - 1] : std::numeric_limits<double>::infinity();
    const Eigen::MatrixXd& V = svd.matrixV();
    s.nullProjector = V.rightCols(n - s.rank) * V.rightCols(n - s.rank).transpose();
    s.variance = Eigen::VectorXd::Zero(n);
    for (int i = 0; i < s.rank; ++i) s.variance += V.col(i).cwiseAbs2() / (sv[i] * sv[i]);
    return s;
}

bool identifiedAll(const SetScore& s, const std::vector<int>& which) {
    for (int i : which)
        if (s.nullProjector(i, i) > 1e-6) return false;
    return true;
}

bool fullRank(const SetScore& s, int n) { return s.rank == n; }

/// Columns (flat indices) of deviations, and per deviation the positions of its columns.
struct Columns {
    std::vector<int> flat;
    std::vector<std::vector<int>> positions;  ///< per deviation of the list, indices into flat
};
Columns columnsOf(const MachineModel& m, const std::vector<int>& devs) {
    Columns c;
    for (int d : devs) {
        std::vector<int> pos;
        for (int k = 0; k < m.deviations[d].size(); ++k) {
            pos.push_back(static_cast<int>(c.flat.size()));
            c.flat.push_back(m.deviations[d].offset + k);
        }
        c.positions.push_back(pos);
    }
    return c;
}

}  // namespace

std::string candidateName(const BallbarRun& r) {
    std::string s(testName(r.test));
    s += fmt::format("_LB{:g}_RB{:g}", r.LB, r.RB);
    if (!rotatesHead(r.test)) s += fmt::format("_RC{:g}", r.RC);
    s += fmt::format("_ZC{:g}", r.ZC);
    return s;
}

namespace {

void checkPlannerOptions(const MachineModel& m, const PlannerOptions& o) {
    if (o.identify.empty()) throw ModelError("the planner needs at least one deviation to identify");
    if (o.LB.empty() || o.RB.empty() || o.RC.empty() || o.ZC.empty())
        throw ModelError("every candidate geometry list (LB, RB, RC, ZC) needs at least one value");
    if (!(o.evaluationStepDeg > 0) || !(o.planStepDeg > 0)) throw ModelError("angle steps must be positive");
    if (o.maxRuns < 1) throw ModelError("the plan needs room for at least one run");
    if (o.mounting != "none" && o.mounting != "tool" && o.mounting != "work" && o.mounting != "both")
        throw ModelError(fmt::format("mounting '{}' is not none, tool, work or both", o.mounting));
    if (o.observe != "traces" && o.observe != "eccentricity")
        throw ModelError(fmt::format("observe '{}' is not traces or eccentricity", o.observe));
    if (o.observe == "eccentricity" && o.mounting != "none")
        throw ModelError("an eccentricity cannot separate mounting offsets: use --mounting none with eccentricities");
    for (int d : o.identify)
        if (d < 0 || d >= static_cast<int>(m.deviations.size())) throw ModelError("deviation index outside the machine");
}

/// One candidate run: simulated on the nominal machine, differentiated by every deviation, the mounting offsets'
/// share eliminated; its R factor scaled to the plan's step. Throws ModelError when the run does not fit the machine.
Candidate candidateOf(const MachineModel& m, const Kinematics& nominal, const std::vector<int>& allDevs, BallbarRun r,
                      const PlannerOptions& o) {
    Observations obs;
    if (o.observe == "eccentricity")
        obs.push_back(std::make_unique<EccentricityObservation>(m, r, simulateRun(nominal, r)));
    else
        obs.push_back(std::make_unique<BallbarObservation>(m, r, simulateRun(nominal, r)));
    const UnknownLayout layout(m, allDevs, obs);
    const LsqProblem p(m, obs, layout, DeviationSet(m));
    Eigen::MatrixXd J;
    p.jacobian(p.start(), J);
    const int nd = layout.deviationUnknowns();
    Eigen::MatrixXd A = J.leftCols(nd);
    if (J.cols() > nd) {  // A ← (I − B B⁺) A: what the mounting offsets cannot absorb
        const Eigen::MatrixXd B = J.rightCols(J.cols() - nd);
        A -= B * B.completeOrthogonalDecomposition().solve(A);
    }
    Eigen::HouseholderQR<Eigen::MatrixXd> qr(A);
    Candidate c;
    c.R = qr.matrixQR().topRows(std::min<Eigen::Index>(A.rows(), nd)).triangularView<Eigen::Upper>();
    // Information per sample of the plan step (ratio of sample counts).
    c.R *= std::sqrt(o.evaluationStepDeg / o.planStepDeg);
    r.stepDeg = o.planStepDeg;
    c.run = r;
    if (c.R.rows() < nd) {  // pad so every block has N rows
        Eigen::MatrixXd pad = Eigen::MatrixXd::Zero(nd, nd);
        pad.topRows(c.R.rows()) = c.R;
        c.R = pad;
    }
    return c;
}

/// Candidates: every run type of `types` × the geometry lists (a head run takes the first RC only); the ones that do
/// not fit the machine are listed in out.rejected.
std::vector<Candidate> candidates(const MachineModel& m, const PlannerOptions& o, const std::vector<BallbarTest>& types,
                                  PlanProposal& out) {
    const Kinematics nominal(m);
    std::vector<int> allDevs;
    for (int i = 0; i < static_cast<int>(m.deviations.size()); ++i) allDevs.push_back(i);
    std::vector<Candidate> cands;
    for (BallbarTest t : types) {
        const bool head = rotatesHead(t);
        const char* axisName = head ? "B" : "C";
        if (m.axisIndex(axisName) < 0) {
            out.rejected.push_back(fmt::format("{}: machine '{}' has no {} axis", testName(t), m.name, axisName));
            continue;
        }
        const Link& axis = m.axisLink(m.requireAxis(axisName));
        const std::vector<double> rcs = head ? std::vector<double>{o.RC[0]} : o.RC;
        for (double LB : o.LB)
            for (double RB : o.RB)
                for (double RC : rcs)
                    for (double ZC : o.ZC) {
                        BallbarRun r;
                        r.test = t;
                        r.LB = LB;
                        r.RB = RB;
                        r.RC = RC;
                        r.ZC = ZC;
                        if (head) {
                            r.startDeg = std::max(-180.0, axis.min / kDeg);
                            r.endDeg = std::min(180.0, axis.max / kDeg);
                        } else {
                            r.startDeg = 0;
                            r.endDeg = 360;
                        }
                        r.stepDeg = o.evaluationStepDeg;
                        r.estimateToolBallOffset = o.mounting == "tool" || o.mounting == "both";
                        r.estimateWorkBallOffset = o.mounting == "work" || o.mounting == "both";
                        r.name = candidateName(r);
                        ++out.candidates;
                        try {
                            cands.push_back(candidateOf(m, nominal, allDevs, r, o));
                        } catch (const ModelError& e) {
                            out.rejected.push_back(fmt::format("{}: {}", r.name, e.what()));
                        }
                    }
    }
    return cands;
}

/// The greedy choice among the candidates, with the chosen ones (indices) and their score.
struct Selection {
    const std::vector<Candidate>& cands;
    std::vector<int> chosen;
    SetScore current;

    std::vector<const Candidate*> setOf(const std::vector<int>& idx) const {
        std::vector<const Candidate*> s;
        for (int i : idx) s.push_back(&cands[i]);
        return s;
    }
    bool isChosen(int i) const { return std::find(chosen.begin(), chosen.end(), i) != chosen.end(); }
    SetScore scoreWith(int extra, const std::vector<int>& cols, double rankTol) const {
        std::vector<int> trial = chosen;
        trial.push_back(extra);
        return score(setOf(trial), cols, rankTol);
    }
    SetScore scoreWithout(size_t k, const std::vector<int>& cols, double rankTol) const {
        std::vector<int> without = chosen;
        without.erase(without.begin() + static_cast<long>(k));
        return score(setOf(without), cols, rankTol);
    }
};

/// Adds the run that raises the rank most (then the information), until the requested columns are all observable.
void addForRank(Selection& sel, const std::vector<int>& cols, int n, const PlannerOptions& o, PlanProposal& out) {
    while (sel.current.rank < n && static_cast<int>(sel.chosen.size()) < o.maxRuns) {
        int best = -1;
        SetScore bestScore;
        for (int i = 0; i < static_cast<int>(sel.cands.size()); ++i) {
            if (sel.isChosen(i)) continue;
            const SetScore s = sel.scoreWith(i, cols, o.rankTolerance);
            if (best < 0 || s.rank > bestScore.rank || (s.rank == bestScore.rank && s.logDet > bestScore.logDet)) {
                best = i;
                bestScore = s;
            }
        }
        if (best < 0 || bestScore.rank <= sel.current.rank) break;  // no run adds an observable direction
        sel.chosen.push_back(best);
        sel.current = bestScore;
        out.steps.push_back(fmt::format("add {}: rank {}/{}, condition number {:.4g}", sel.cands[best].run.name,
                                        sel.current.rank, n, sel.current.condition));
    }
}

/// Adds the run that lowers the condition number most, while it is above the target.
void addForConditioning(Selection& sel, const std::vector<int>& cols, const PlannerOptions& o, PlanProposal& out) {
    while (sel.current.condition > o.targetCondition && static_cast<int>(sel.chosen.size()) < o.maxRuns) {
        int best = -1;
        SetScore bestScore = sel.current;
        for (int i = 0; i < static_cast<int>(sel.cands.size()); ++i) {
            if (sel.isChosen(i)) continue;
            const SetScore s = sel.scoreWith(i, cols, o.rankTolerance);
            if (s.condition < bestScore.condition) {
                best = i;
                bestScore = s;
            }
        }
        if (best < 0 || bestScore.condition > 0.99 * sel.current.condition) break;
        sel.chosen.push_back(best);
        sel.current = bestScore;
        out.steps.push_back(fmt::format("add {} for conditioning: condition number {:.4g}", sel.cands[best].run.name,
                                        sel.current.condition));
    }
}

/// Prunes runs the request can do without (within the target, or without getting worse).
void pruneRuns(Selection& sel, const std::vector<int>& cols, int n, const PlannerOptions& o, PlanProposal& out) {
    for (bool removed = true; removed && sel.chosen.size() > 1;) {
        removed = false;
        int bestPos = -1;
        SetScore bestScore;
        for (size_t k = 0; k < sel.chosen.size(); ++k) {
            const SetScore s = sel.scoreWithout(k, cols, o.rankTolerance);
            if (!fullRank(s, n) || s.condition > std::max(o.targetCondition, sel.current.condition)) continue;
            if (bestPos < 0 || s.condition < bestScore.condition) {
                bestPos = static_cast<int>(k);
                bestScore = s;
            }
        }
        if (bestPos >= 0) {
            out.steps.push_back(fmt::format("drop {}: still identifiable, condition number {:.4g}",
                                            sel.cands[sel.chosen[bestPos]].run.name, bestScore.condition));
            sel.chosen.erase(sel.chosen.begin() + bestPos);
            sel.current = bestScore;
            removed = true;
        }
    }
}

/// Requested deviation di of the plan: identified or not (and with what it is confounded), its σ, the runs that see
/// it and the runs it cannot do without.
DeviationNeed explainNeed(const MachineModel& m, const PlannerOptions& o, const Selection& sel, const Columns& target,
                          size_t di) {
    const int n = static_cast<int>(target.flat.size());
    const SetScore& current = sel.current;
    const std::vector<int>& chosen = sel.chosen;
    DeviationNeed need;
    need.deviation = o.identify[di];
    need.name = m.deviations[need.deviation].name;
    need.alias = m.deviations[need.deviation].alias;
    const std::vector<int>& pos = target.positions[di];
    need.identified = identifiedAll(current, pos);
    for (int p : pos) need.sigmaPerUm = std::max(need.sigmaPerUm, kUm * std::sqrt(current.variance[p]));
    if (!need.identified) {
        need.sigmaPerUm = std::numeric_limits<double>::quiet_NaN();
        for (int j = 0; j < n; ++j) {
            bool coupled = false;
            for (int p : pos) coupled = coupled || (std::abs(current.nullProjector(p, j)) > 1e-6);
            if (coupled && std::find(pos.begin(), pos.end(), j) == pos.end()) {
                // name of the deviation owning column j
                for (size_t dj = 0; dj < o.identify.size(); ++dj)
                    if (std::find(target.positions[dj].begin(), target.positions[dj].end(), j) != target.positions[dj].end()) {
                        const std::string& nm = m.deviations[o.identify[dj]].name;
                        if (std::find(need.confoundedWith.begin(), need.confoundedWith.end(), nm) == need.confoundedWith.end())
                            need.confoundedWith.push_back(nm);
                    }
            }
        }
    }
    double strongest = 0;
    std::vector<double> strength;
    for (int c : chosen) {
        double s = 0;
        for (int p : pos) s += sel.cands[c].R.col(target.flat[p]).squaredNorm();
        strength.push_back(std::sqrt(s));
        strongest = std::max(strongest, strength.back());
    }
    for (size_t k = 0; k < chosen.size(); ++k) {
        if (strength[k] >= 0.05 * strongest && strongest > 0) need.seenBy.push_back(sel.cands[chosen[k]].run.name);
        if (!need.identified) continue;
        if (!identifiedAll(sel.scoreWithout(k, target.flat, o.rankTolerance), pos))
            need.needs.push_back(sel.cands[chosen[k]].run.name);
    }
    return need;
}

/// Another deviation d of the machine: the run types that see it, and whether the plan identifies it too (with the
/// runs it needs) or which extra run would, best first.
ExtraAdvice adviseOther(const MachineModel& m, const PlannerOptions& o, const Selection& sel, int d) {
    const std::vector<Candidate>& cands = sel.cands;
    const std::vector<int>& chosen = sel.chosen;
    ExtraAdvice a;
    a.deviation = d;
    a.name = m.deviations[d].name;
    a.alias = m.deviations[d].alias;
    std::vector<int> devs = o.identify;
    devs.push_back(d);
    const Columns cols = columnsOf(m, devs);
    const std::vector<int>& pos = cols.positions.back();
    const int nn = static_cast<int>(cols.flat.size());
    {
        std::vector<double> strength;
        double strongest = 0;
        for (const Candidate& c : cands) {
            double v = 0;
            for (int p : pos) v += c.R.col(cols.flat[p]).squaredNorm();
            strength.push_back(std::sqrt(v));
            strongest = std::max(strongest, strength.back());
        }
        for (size_t i = 0; i < cands.size(); ++i) {
            const std::string type(testName(cands[i].run.test));
            if (strongest > 0 && strength[i] >= 0.05 * strongest &&
                std::find(a.seenByTypes.begin(), a.seenByTypes.end(), type) == a.seenByTypes.end())
                a.seenByTypes.push_back(type);
        }
    }
    const SetScore s = score(sel.setOf(chosen), cols.flat, o.rankTolerance);
    if (fullRank(s, nn)) {
        a.identifiedByPlan = true;
        for (int p : pos) a.sigmaPerUm = std::max(a.sigmaPerUm, kUm * std::sqrt(s.variance[p]));
        for (size_t k = 0; k < chosen.size(); ++k)
            if (!identifiedAll(sel.scoreWithout(k, cols.flat, o.rankTolerance), pos))
                a.needs.push_back(cands[chosen[k]].run.name);
    } else {
        std::vector<std::pair<double, std::string>> options;
        for (int i = 0; i < static_cast<int>(cands.size()); ++i) {
            if (sel.isChosen(i)) continue;
            const SetScore t = sel.scoreWith(i, cols.flat, o.rankTolerance);
            if (!fullRank(t, nn)) continue;
            double sigma = 0;
            for (int p : pos) sigma = std::max(sigma, kUm * std::sqrt(t.variance[p]));
            options.emplace_back(sigma, cands[i].run.name);
        }
        std::sort(options.begin(), options.end());
        for (const auto& [sig, name] : options) {
            a.extraRuns.push_back(name);
            a.extraSigmaPerUm.push_back(sig);
        }
    }
    return a;
}

}  // namespace

PlanProposal proposePlan(const MachineModel& m, const PlannerOptions& o) {
    checkPlannerOptions(m, o);
    PlanProposal out;
    const bool hasXYZ = m.axisIndex("X") >= 0 && m.axisIndex("Y") >= 0 && m.axisIndex("Z") >= 0;
    std::vector<BallbarTest> types = o.types;
    if (types.empty())
        for (BallbarTest t : kAllBallbarTests)
            if (m.axisIndex(rotatesHead(t) ? "B" : "C") >= 0) types.push_back(t);
    if (!hasXYZ || types.empty())
        throw ModelError(fmt::format("machine '{}' allows no ball-bar run of the twelve run types (needs X, Y, Z and a B "
                                     "head or C table axis)", m.name));
    const std::vector<Candidate> cands = candidates(m, o, types, out);
    if (cands.empty())
        throw ModelError(fmt::format("no candidate run fits machine '{}'{}", m.name,
                                     out.rejected.empty() ? "" : " (e.g. " + out.rejected.front() + ")"));

    // Greedy selection over the requested columns: rank first, then conditioning, then pruning.
    const Columns target = columnsOf(m, o.identify);
    const int n = static_cast<int>(target.flat.size());
    Selection sel{cands, {}, score({}, target.flat, o.rankTolerance)};
    addForRank(sel, target.flat, n, o, out);
    if (sel.current.rank == n) {
        addForConditioning(sel, target.flat, o, out);
        pruneRuns(sel, target.flat, n, o, out);
    }
    // Plan order: the order of Table 2 types, then geometry.
    std::sort(sel.chosen.begin(), sel.chosen.end());
    sel.current = score(sel.setOf(sel.chosen), target.flat, o.rankTolerance);
    out.rank = sel.current.rank;
    out.unknowns = n;
    out.conditionNumber = sel.current.condition;
    out.complete = sel.current.rank == n;
    out.plan.machine = m.name;
    std::string list;
    for (int d : o.identify) list += (list.empty() ? "" : " ") + m.deviations[d].name;
    out.plan.description = fmt::format("proposed by cnccomp plan to identify {}", list);
    for (int i : sel.chosen) out.plan.runs.push_back(cands[i].run);

    for (size_t di = 0; di < o.identify.size(); ++di) out.needs.push_back(explainNeed(m, o, sel, target, di));
    // The machine's other deviations: identified by the plan too, or what extra run would identify them.
    for (int d = 0; d < static_cast<int>(m.deviations.size()); ++d)
        if (std::find(o.identify.begin(), o.identify.end(), d) == o.identify.end())
            out.others.push_back(adviseOther(m, o, sel, d));
    return out;
}

}  // namespace cnccomp::identification
