// The values a controller's files carry, fitted to what that controller holds.
//
// The backend is a black box: emit() writes files from a deviation set, apply() reads them back into the controller's
// model. The free values are the entries of the deviation vector the files respond to, found from the finite-difference
// Jacobian of the tool-tip error itself (a column that is zero: the files ignore that value). The objective is
// Σ |tip error|² of the IDENTIFIED machine over the workspace's poses at each of its tool lengths (orientation errors
// enter through the tool lengths: the tip at 0 and at 360 mm differ by the tool-axis error × 360 mm). The compensation
// is linear in the values to first order (µm against metres of lever), so one Jacobian at zero and a few chord steps
// (Gauss-Newton with the Jacobian kept) converge; the solve is an SVD of the column-scaled Jacobian, truncated at
// 1e-9 of the largest singular value, i.e. the minimum-norm values where several move the files the same way
// (redundant values). Oracle of the method: finite differences of the backend's own emit/apply round trip.
//
// Two guards against a fit running away where the workspace does not look (found on fanuc-30i, table-table-ac, the
// truth set, a 5-per-axis grid: the figures said 164.5 -> 129.5 um while `cnccomp verify` measured the R-test span
// 76.6 -> 63834 um):
// - A grid of a few samples per axis sees a table-basis component (EAA, ECC: a node every 15 / 30 deg) only at the
//   nodes under a sample; the others have a zero column, stay zero, and the fitted nodes are free to move together.
//   Every axis is therefore also swept alone through its travel (kSweep positions, the others at 0): in the fit's own
//   sample and in the figures the candidates are judged on, so a fit that is good on the grid and absurd between its
//   samples is seen, and "none" or the copy is written instead (fitFigures judges the same poses).
// - A direction the files cannot hold answers only through their rounding: a pitch table is written relative to its
//   reference position (controllers/fanuc/pitch_error.hpp: zero there), so all nodes of EAA moving together change
//   nothing but the rounding of the data to detection units. Its singular value is not zero but ~1e-5 of the largest
//   (measured: 7.8e-6, 4.9e-6 for EAA and ECC), and the minimum-norm solve took 0.162 rad (9.3 deg) along it. The
//   SVD is truncated at kSvdFloor of the largest singular value: a column is a 5 um / 10 arcsec move, so a
//   combination moving the tool tip by less than 1e-4 of the strongest such move (0.5 nm against 5 um) is below the
//   files' rounding and is not fitted. Each chord step is also bounded (kMaxStepMoves of those moves per value).
#include "controllers/common/fit.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/SVD>
#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/inverse_kinematics.hpp"
#include "controllers/common/evaluate.hpp"

namespace cnccomp::controllers::common {
namespace {

constexpr double kLengthStep = 5e-3;   ///< mm: finite-difference step of a length value (5 um)
constexpr double kAngleStep = 5e-5;    ///< rad: of an angle value (about 10 arcsec)
constexpr int kFitPoses = 400;         ///< poses per tool length the fit itself looks at (evenly spread subset)
constexpr int kChordSteps = 4;
constexpr int kSweep = 121;            ///< positions of each axis' own sweep through its travel (3 deg over 360 deg)
constexpr double kSweepWeight = 0.4;   ///< factor on the sweeps' rows in the fit (0.16 in the sum of squares): they pin
                                       ///< every node of a table but do not outweigh the workspace (measured on the
                                       ///< quickstart Fanuc case: at full weight the single-axis moves pulled the fit's
                                       ///< largest tip error from 56.2 to 61.7 um; at 0.25 the table-table-ac R-test span
                                       ///< rose 76.574 -> 77.580 um, at 0.4 it stays 76.574 um)
constexpr double kSvdFloor = 1e-4;     ///< singular values below this fraction of the largest are not fitted
constexpr double kMaxStepMoves = 100;  ///< largest change of one value per chord step, in finite-difference steps
                                       ///< (0.5 mm / 1000 arcsec): beyond it the linear model is not trusted

/// Each axis alone through its travel (linear axes within +-200 mm, rotary within +-180 deg, as workspaceSamples), the
/// others at 0 (or the nearest end of their travel).
std::vector<AxisVector> axisSweeps(const MachineModel& m) {
    const int n = m.axisCount();
    std::vector<double> lo(static_cast<size_t>(n)), hi(static_cast<size_t>(n));
    AxisVector home(n);
    for (int i = 0; i < n; ++i) {
        const Link& l = m.axisLink(i);
        const double lim = l.kind == AxisKind::Rotary ? kPi : 200.0;
        lo[static_cast<size_t>(i)] = std::max(l.min, -lim);
        hi[static_cast<size_t>(i)] = std::min(l.max, lim);
        home[i] = std::clamp(0.0, l.min, l.max);
    }
    std::vector<AxisVector> out;
    for (int i = 0; i < n; ++i) {
        if (!(hi[static_cast<size_t>(i)] > lo[static_cast<size_t>(i)])) continue;
        for (int k = 0; k < kSweep; ++k) {
            AxisVector q = home;
            q[i] = lo[static_cast<size_t>(i)] + (hi[static_cast<size_t>(i)] - lo[static_cast<size_t>(i)]) * k / (kSweep - 1);
            out.push_back(q);
        }
    }
    return out;
}


/// Files of `b` for `d`, read back.
std::unique_ptr<AppliedCompensation> filesFor(const Backend& b, const MachineModel& m, const DeviationSet& d) {
    const EmitRequest request{m, d, "fit", "2000-01-01"};
    auto comp = b.apply(m, b.emit(request).files);
    if (!comp) throw ModelError(fmt::format("backend '{}' returned no compensation model", b.name()));
    return comp;
}

/// Tip error vectors of the identified machine at a fixed set of poses and tool lengths.
class TipResidual {
public:
    /// Poses from `lightFrom` on (the axis sweeps) weigh kSweepWeight in each row.
    TipResidual(const Backend& b, const MachineModel& m, const DeviationSet& identified, std::vector<AxisVector> poses,
                std::vector<double> toolLengths, size_t lightFrom)
        : b_(b), m_(m), nominal_(m), actual_(m, identified), poses_(std::move(poses)), lengths_(std::move(toolLengths)),
          lightFrom_(lightFrom) {
        for (double L : lengths_) {
            const Vec3 tip = nominal_.toolPoint(L);
            for (const AxisVector& q : poses_) targets_.push_back(toolPose(nominal_, q, tip).tip);
        }
    }
    int size() const { return 3 * static_cast<int>(targets_.size()); }
    Eigen::VectorXd operator()(const DeviationSet& d) const {
        const auto comp = filesFor(b_, m_, d);
        Eigen::VectorXd r(size());
        size_t k = 0;
        for (double L : lengths_) {
            const Vec3 tip = nominal_.toolPoint(L);
            for (size_t i = 0; i < poses_.size(); ++i) {
                const AxisVector& q = poses_[i];
                const AxisVector drive = comp->driveCommandsForTool(q, L);
                if (drive.size() != q.size() || !drive.allFinite())
                    throw ModelError(fmt::format("backend '{}': drive commands of the wrong size or not finite", b_.name()));
                r.segment<3>(static_cast<Eigen::Index>(3 * k)) =
                    (toolPose(actual_, drive, tip).tip - targets_[k]) * (i >= lightFrom_ ? kSweepWeight : 1.0);
                ++k;
            }
        }
        return r;
    }

private:
    const Backend& b_;
    const MachineModel& m_;
    Kinematics nominal_, actual_;
    std::vector<AxisVector> poses_;
    std::vector<double> lengths_;
    std::vector<Vec3> targets_;
    size_t lightFrom_;
};

/// The deviation (index into m.deviations) of each entry of the flat vector.
std::vector<int> ownerOfEntries(const MachineModel& m, Eigen::Index n) {
    std::vector<int> owner(static_cast<size_t>(n), -1);
    for (size_t d = 0; d < m.deviations.size(); ++d)
        for (int j = 0; j < m.deviations[d].size(); ++j) owner[static_cast<size_t>(m.deviations[d].offset + j)] = static_cast<int>(d);
    return owner;
}

/// Finite-difference step of entry j: a location value moves by 5 um / 10 arcsec; a component coefficient by what
/// makes its basis function reach that over the axis' travel.
double stepOf(const MachineModel& m, const DeviationDef& def, int j) {
    const double target = def.isAngle() ? kAngleStep : kLengthStep;
    if (def.kind == DeviationKind::Location) return target;
    const Link& l = m.chain(def.side).links[static_cast<size_t>(def.link)];
    const double lim = l.kind == AxisKind::Rotary ? kPi : 1e4;
    const double lo = std::max(l.min, -lim), hi = std::min(l.max, lim);
    std::vector<double> coef(static_cast<size_t>(def.size()), 0.0);
    coef[static_cast<size_t>(j)] = 1.0;
    double peak = 0;
    for (int s = 0; s <= 20; ++s) {
        const double q = hi > lo ? lo + (hi - lo) * s / 20.0 : lo;
        peak = std::max(peak, std::abs(def.basis.evaluate(q, coef.data(), l.modulo)));
    }
    return peak > 1e-12 ? target / peak : target;
}

FitFigures figuresOf(const MachineModel& m, const DeviationSet& identified, const AppliedCompensation& comp,
                     const FitWorkspace& w) {
    FitFigures f;
    double sum = 0;
    long points = 0;
    for (double L : w.toolLengths) {
        const CompensationFigures c = evaluateCompensation(m, identified, comp, w.poses, L);
        f.maxTip = std::max(f.maxTip, c.maxAfter);
        f.maxAxis = std::max(f.maxAxis, c.maxAxisAfter);
        sum += c.rmsAfter * c.rmsAfter * c.points;
        points += c.points;
    }
    if (points > 0) f.rmsTip = std::sqrt(sum / static_cast<double>(points));
    return f;
}

/// The choice among the candidates: the smallest RMS among those whose largest error is not above none's (none always
/// qualifies); `fitted` null where no fit was made. Sets out.written and out.chosen.
void chooseCandidate(FitOutcome& out, const DeviationSet& zero, const DeviationSet& identified, const DeviationSet* fitted) {
    const double noneMax = out.none.maxTip;
    const auto qualifies = [&](const FitFigures& f) { return f.maxTip <= noneMax; };
    out.written = zero;
    out.chosen = "none";
    double best = out.none.rmsTip;
    if (qualifies(out.copied) && out.copied.rmsTip < best) out.written = identified, out.chosen = "identified", best = out.copied.rmsTip;
    if (fitted && qualifies(out.fitted) && out.fitted.rmsTip < best) out.written = *fitted, out.chosen = "fitted";
}

std::string describe(const FitFigures& f) { return fmt::format("tip max {:.3f} um, RMS {:.3f} um", f.maxTip / kUm, f.rmsTip / kUm); }

}  // namespace

FitWorkspace judgedWorkspace(const MachineModel& m, const FitWorkspace& w) {
    FitWorkspace j = w;
    const std::vector<AxisVector> s = axisSweeps(m);
    j.poses.insert(j.poses.end(), s.begin(), s.end());
    j.description += fmt::format(" + each axis alone through its travel ({} positions each)", kSweep);
    return j;
}

FitFigures fitFigures(const Backend& b, const MachineModel& m, const DeviationSet& identified, const DeviationSet& written,
                      const FitWorkspace& workspace) {
    return figuresOf(m, identified, *filesFor(b, m, written), judgedWorkspace(m, workspace));
}

bool leavesMore(const FitFigures& a, const FitFigures& b) {
    const auto more = [](double x, double y) { return x > y + std::max(kFitTolerance.absolute, kFitTolerance.relative * y); };
    return more(a.maxTip, b.maxTip) || more(a.rmsTip, b.rmsTip);
}

FitOutcome fitControllerValues(const Backend& b, const MachineModel& m, const DeviationSet& identified,
                               const FitWorkspace& given) {
    if (given.poses.empty() || given.toolLengths.empty())
        throw ModelError("fit of the controller's values: the workspace has no poses or no tool lengths");
    if (!identified.values.allFinite()) throw ModelError("the deviation set holds a value that is not a finite number");
    const Eigen::Index n = identified.values.size();
    const FitWorkspace workspace = judgedWorkspace(m, given);  // the workspace and each axis' sweep (see the top of the file)
    const size_t sweeps = workspace.poses.size() - given.poses.size();
    // The candidates: no compensation (the files written with every value zero), the identified values copied.
    DeviationSet zero = identified;
    zero.values.setZero();
    FitOutcome out{identified, "identified", {}, {}, {}, {}, {}, -1};
    out.none = figuresOf(m, identified, *filesFor(b, m, zero), workspace);
    out.copied = figuresOf(m, identified, *filesFor(b, m, identified), workspace);
    const double noneMax = out.none.maxTip;

    // The copy leaves (next to) nothing: the controller holds every deviation; the fit is the identified values.
    if (out.copied.maxTip <= std::max(kHoldsAllFraction * noneMax, kFitTolerance.absolute)) {
        out.fitted = out.copied;
        out.fittedValues = identified;
        out.chosen = "fitted";
        out.notes.push_back(fmt::format("values fitted to this controller over {}: the controller holds every deviation given, "
                                        "the fit is the identified values (tool-tip error {} -> {})",
                                        workspace.description, describe(out.none), describe(out.copied)));
        return out;
    }

    // Files that hold the error itself, sampled (Backend::fitsDeviationValues): the candidates are none and the copy.
    // Measured before this rule, the generic map on the HEIDENHAIN component sample: 99 s of fitting (Release, 2 cores
    // shared) for a fit that left more than the copy (RMS 2.269 against 1.997 um) and was not written.
    if (!b.fitsDeviationValues()) {
        out.fitted = out.copied;
        out.fittedValues = identified;
        chooseCandidate(out, zero, identified, nullptr);
        const bool copy = out.chosen == "identified";
        out.notes.push_back(fmt::format("values not fitted to this controller: its files hold the error itself, sampled over {}",
                                        workspace.description));
        out.notes.push_back(fmt::format("tool-tip error predicted on the identified machine: none {}; identified values copied {}",
                                        describe(out.none), describe(out.copied)));
        out.notes.push_back(fmt::format("written: {}", copy ? "the identified values" : "zero values (the copy left more than none)"));
        return out;
    }

    // The fit's own sample: an evenly spread subset of the poses (every tool length).
    std::vector<AxisVector> sub;
    const size_t np = given.poses.size();
    const size_t count = std::min<size_t>(np, kFitPoses);
    for (size_t i = 0; i < count; ++i) sub.push_back(given.poses[i * np / count]);
    const size_t lightFrom = sub.size();
    sub.insert(sub.end(), workspace.poses.end() - static_cast<std::ptrdiff_t>(sweeps), workspace.poses.end());
    const TipResidual residual(b, m, identified, sub, workspace.toolLengths, lightFrom);

    // Jacobian at zero over every entry of the deviation vector; the files respond to the entries with a column.
    const std::vector<int> owner = ownerOfEntries(m, n);
    const Eigen::VectorXd r0 = residual(zero);
    std::vector<Eigen::Index> free;
    std::vector<Eigen::VectorXd> columns;
    std::vector<double> steps;
    for (Eigen::Index j = 0; j < n; ++j) {
        const int d = owner[static_cast<size_t>(j)];
        if (d < 0) continue;
        const DeviationDef& def = m.deviations[static_cast<size_t>(d)];
        const double h = stepOf(m, def, static_cast<int>(j - def.offset));
        DeviationSet p = zero;
        p.values[j] = h;
        p.present[static_cast<size_t>(d)] = 1;
        Eigen::VectorXd col;
        try {
            col = (residual(p) - r0) / h;
        } catch (const ModelError&) {
            continue;  // the controller refuses the value (e.g. a pitch table's data range): not a value it holds
        }
        if ((col * h).lpNorm<Eigen::Infinity>() <= 1e-7) continue;  // the drives do not move by 0.1 nm: not held
        free.push_back(j);
        columns.push_back(col);
        steps.push_back(h);
    }
    const int p = static_cast<int>(free.size());
    std::string held;
    for (int k = 0; k < p; ++k) {
        const int d = owner[static_cast<size_t>(free[static_cast<size_t>(k)])];
        const std::string& name = m.deviations[static_cast<size_t>(d)].name;
        if (held.find(" " + name + ",") == std::string::npos && held.find(" " + name + "[") == std::string::npos)
            held += fmt::format(" {}{},", name, m.deviations[static_cast<size_t>(d)].kind == DeviationKind::Location ? "" : "[]");
    }
    if (!held.empty()) held.pop_back();
    out.heldValues = p;

    DeviationSet fitted = zero;
    const auto setFree = [&](const Eigen::VectorXd& x) {
        DeviationSet s = zero;
        for (int k = 0; k < p; ++k) {
            const Eigen::Index j = free[static_cast<size_t>(k)];
            s.values[j] = x[k];
            if (x[k] != 0) s.present[static_cast<size_t>(owner[static_cast<size_t>(j)])] = 1;
        }
        return s;
    };
    if (p > 0) {
        // Columns scaled by their steps (each a 5 um / 10 arcsec move): the SVD compares like with like.
        Eigen::MatrixXd J(r0.size(), p);
        for (int k = 0; k < p; ++k) J.col(k) = columns[static_cast<size_t>(k)] * steps[static_cast<size_t>(k)];
        Eigen::BDCSVD<Eigen::MatrixXd> svd(J, Eigen::ComputeThinU | Eigen::ComputeThinV);
        svd.setThreshold(kSvdFloor);
        const Eigen::VectorXd scale = Eigen::Map<const Eigen::VectorXd>(steps.data(), p);
        Eigen::VectorXd x = Eigen::VectorXd::Zero(p);
        Eigen::VectorXd r = r0;
        double cost = r.squaredNorm();
        // Start from the identified values of the held entries where they leave less than zero: the chord steps
        // (the Jacobian at zero) then improve on the copy instead of on nothing, which matters where the files answer
        // non-linearly (measured: Siemens on the HEIDENHAIN component sample, Fanuc on the B/C table with offsets).
        {
            Eigen::VectorXd xi(p);
            for (int k = 0; k < p; ++k) xi[k] = identified.values[free[static_cast<size_t>(k)]];
            try {
                const Eigen::VectorXd ri = residual(setFree(xi));
                if (ri.squaredNorm() < cost) x = xi, r = ri, cost = ri.squaredNorm();
            } catch (const ModelError&) {
                // the controller refuses the identified values: start from zero
            }
        }
        for (int it = 0; it < kChordSteps; ++it) {
            Eigen::VectorXd dx = -(svd.solve(r)).cwiseProduct(scale);
            const double moves = (dx.cwiseQuotient(scale)).lpNorm<Eigen::Infinity>();
            if (moves > kMaxStepMoves) dx *= kMaxStepMoves / moves;
            double t = 1.0;
            bool better = false;
            for (int halving = 0; halving < 6 && !better; ++halving, t *= 0.5) {
                const Eigen::VectorXd xt = x + t * dx;
                try {
                    const Eigen::VectorXd rt = residual(setFree(xt));
                    if (rt.squaredNorm() < cost) x = xt, r = rt, better = true;
                } catch (const ModelError&) {
                    // beyond a limit of the controller: a shorter step
                }
            }
            if (!better) break;
            const double before = cost;
            cost = r.squaredNorm();
            if (before - cost <= 1e-6 * before) break;
        }
        // The constant part of a component the files hold only relative to a reference (a pitch table: zero at its
        // reference position) is not a value they carry; whatever of it the solve left is taken out where the files
        // answer the same without it (all held entries of a basis whose all-ones coefficients are the constant 1, e.g.
        // a table's nodes, shifted by minus their mean).
        for (size_t d = 0; d < m.deviations.size(); ++d) {
            const DeviationDef& def = m.deviations[d];
            if (def.kind != DeviationKind::Component) continue;
            std::vector<int> ks;
            for (int k = 0; k < p; ++k)
                if (owner[static_cast<size_t>(free[static_cast<size_t>(k)])] == static_cast<int>(d)) ks.push_back(k);
            if (ks.empty() || static_cast<int>(ks.size()) != def.size()) continue;
            const Link& l = m.chain(def.side).links[static_cast<size_t>(def.link)];
            const std::vector<double> ones(static_cast<size_t>(def.size()), 1.0);
            bool constantIsAllOnes = true;
            for (int s = 0; s <= 12 && constantIsAllOnes; ++s)
                constantIsAllOnes = std::abs(def.basis.evaluate(-kPi + 2 * kPi * s / 12.0, ones.data(), l.modulo) - 1.0) < 1e-12;
            if (!constantIsAllOnes) continue;
            double mean = 0;
            for (int k : ks) mean += x[k];
            mean /= static_cast<double>(ks.size());
            Eigen::VectorXd xs = x;
            for (int k : ks) xs[k] -= mean;
            try {
                const Eigen::VectorXd rs = residual(setFree(xs));
                if (rs.squaredNorm() <= cost * (1 + 1e-3)) x = xs, r = rs, cost = std::min(cost, rs.squaredNorm());
            } catch (const ModelError&) {
                // the controller refuses the shifted values: keep the fit's
            }
        }
        fitted = setFree(x);
    }
    try {
        out.fitted = figuresOf(m, identified, *filesFor(b, m, fitted), workspace);
    } catch (const ModelError&) {
        fitted = zero;  // the controller refuses the fitted values: the fit falls back to none
        out.fitted = out.none;
    }
    out.fittedValues = fitted;

    chooseCandidate(out, zero, identified, &fitted);

    out.notes.push_back(fmt::format("values fitted to this controller (least squares of the tool-tip error of the identified machine) "
                                    "over {}", workspace.description));
    out.notes.push_back(fmt::format("values the files respond to ({}):{}", p, held.empty() ? " none" : held));
    out.notes.push_back(fmt::format("tool-tip error predicted on the identified machine: none {}; identified values copied {}; "
                                    "fitted {}",
                                    describe(out.none), describe(out.copied), describe(out.fitted)));
    out.notes.push_back(fmt::format("written: {}", out.chosen == "fitted"       ? "the fitted values"
                                                   : out.chosen == "identified" ? "the identified values copied (the fit left more)"
                                                                                : "zero values (every other candidate left more than none)"));
    return out;
}

}  // namespace cnccomp::controllers::common
