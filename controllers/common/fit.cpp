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
#include "controllers/common/fit.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/SVD>
#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/inverse_kinematics.hpp"
#include "controllers/common/evaluate.hpp"

namespace cnccomp::controllers {
namespace {

constexpr double kLengthStep = 5e-3;   ///< mm: finite-difference step of a length value (5 um)
constexpr double kAngleStep = 5e-5;    ///< rad: of an angle value (about 10 arcsec)
constexpr int kFitPoses = 400;         ///< poses per tool length the fit itself looks at (evenly spread subset)
constexpr int kChordSteps = 4;

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
    TipResidual(const Backend& b, const MachineModel& m, const DeviationSet& identified, std::vector<AxisVector> poses,
                std::vector<double> toolLengths)
        : b_(b), m_(m), nominal_(m), actual_(m, identified), poses_(std::move(poses)), lengths_(std::move(toolLengths)) {
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
            for (const AxisVector& q : poses_) {
                const AxisVector drive = comp->driveCommandsForTool(q, L);
                if (drive.size() != q.size() || !drive.allFinite())
                    throw ModelError(fmt::format("backend '{}': drive commands of the wrong size or not finite", b_.name()));
                r.segment<3>(static_cast<Eigen::Index>(3 * k)) = toolPose(actual_, drive, tip).tip - targets_[k];
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

std::string describe(const FitFigures& f) { return fmt::format("tip max {:.3f} um, RMS {:.3f} um", f.maxTip / kUm, f.rmsTip / kUm); }

}  // namespace

FitFigures fitFigures(const Backend& b, const MachineModel& m, const DeviationSet& identified, const DeviationSet& written,
                      const FitWorkspace& workspace) {
    return figuresOf(m, identified, *filesFor(b, m, written), workspace);
}

bool leavesMore(const FitFigures& a, const FitFigures& b) {
    const auto more = [](double x, double y) { return x > y + std::max(kFitTolerance.absolute, kFitTolerance.relative * y); };
    return more(a.maxTip, b.maxTip) || more(a.rmsTip, b.rmsTip);
}

FitOutcome fitControllerValues(const Backend& b, const MachineModel& m, const DeviationSet& identified,
                               const FitWorkspace& workspace) {
    if (workspace.poses.empty() || workspace.toolLengths.empty())
        throw ModelError("fit of the controller's values: the workspace has no poses or no tool lengths");
    if (!identified.values.allFinite()) throw ModelError("the deviation set holds a value that is not a finite number");
    const Eigen::Index n = identified.values.size();
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

    // The fit's own sample: an evenly spread subset of the poses (every tool length).
    std::vector<AxisVector> sub;
    const size_t np = workspace.poses.size();
    const size_t count = std::min<size_t>(np, kFitPoses);
    for (size_t i = 0; i < count; ++i) sub.push_back(workspace.poses[i * np / count]);
    const TipResidual residual(b, m, identified, sub, workspace.toolLengths);

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
        svd.setThreshold(1e-9);
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
            const Eigen::VectorXd dx = -(svd.solve(r)).cwiseProduct(scale);
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
        fitted = setFree(x);
    }
    try {
        out.fitted = figuresOf(m, identified, *filesFor(b, m, fitted), workspace);
    } catch (const ModelError&) {
        fitted = zero;  // the controller refuses the fitted values: the fit falls back to none
        out.fitted = out.none;
    }
    out.fittedValues = fitted;

    // The choice: the smallest RMS among the candidates whose largest error is not above none's (none always qualifies).
    const auto qualifies = [&](const FitFigures& f) { return f.maxTip <= noneMax; };
    out.written = zero;
    out.chosen = "none";
    double best = out.none.rmsTip;
    if (qualifies(out.copied) && out.copied.rmsTip < best) out.written = identified, out.chosen = "identified", best = out.copied.rmsTip;
    if (qualifies(out.fitted) && out.fitted.rmsTip < best) out.written = fitted, out.chosen = "fitted", best = out.fitted.rmsTip;

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

}  // namespace cnccomp::controllers
