#include "cnccomp/identification/lsq.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/iso_names.hpp"
#include "cnccomp/identification/adequacy.hpp"
#include "cnccomp/identification/identifiability.hpp"
#include "cnccomp/identification/levenberg_marquardt.hpp"
#include "cnccomp/identification/nlopt_solver.hpp"
#include "cnccomp/identification/problem.hpp"

namespace cnccomp::identification {

namespace {

void boxBounds(const UnknownLayout& L, const IdentifyOptions& o, Eigen::VectorXd& lo, Eigen::VectorXd& hi) {
    lo.resize(L.size());
    hi.resize(L.size());
    for (int i = 0; i < L.size(); ++i) {
        // Default box ± defaultBoundDisplay µm / arcsec (in solver units for a coefficient).
        lo[i] = -o.defaultBoundDisplay;
        hi[i] = o.defaultBoundDisplay;
    }
    for (const ParameterBound& b : o.bounds) {
        int found = -1;
        for (int i = 0; i < L.size(); ++i)
            if (L[i].name == b.name || (!L[i].alias.empty() && L[i].alias == b.name)) found = i;
        if (found >= 0 && !L[found].nuisance && L[found].name != b.name) {
            const DeviationDef& d = L.machine().deviations[static_cast<size_t>(L[found].deviation)];
            if (aliasDiffersFromName(L.machine(), L[found].deviation))
                throw ModelError(fmt::format("bound for '{}': give it under the ISO name '{}' (the unknowns are ISO values)",
                                             b.name, d.name));
        }
        if (found < 0) throw ModelError(fmt::format("bound for '{}', which is not an unknown of this problem", b.name));
        lo[found] = b.lower / L[found].scale;
        hi[found] = b.upper / L[found].scale;
    }
}

/// Sampled uncertainty: synthetic measurements = prediction at x̂ + N(0, σ̂²/w²), solved again from x̂.
void monteCarlo(LsqProblem& p, const ObservableSubspace& sub, const Eigen::VectorXd& x, const IdentifyOptions& o,
                IdentificationReport& rep) {
    if (o.monteCarlo <= 0 || !std::isfinite(rep.sigma)) return;
    Eigen::VectorXd pred;
    p.predict(x, pred);
    std::mt19937_64 rng(o.seed);
    std::normal_distribution<double> gauss(0.0, 1.0);
    SolverSettings s;
    s.maxIterations = std::min(o.maxIterations, 10);
    s.rankTolerance = o.rankTolerance;
    const int n = static_cast<int>(x.size());
    std::vector<std::vector<double>> samples(n);
    const Eigen::VectorXd& w = p.weights();
    for (int t = 0; t < o.monteCarlo; ++t) {
        Eigen::VectorXd y(pred.size());
        for (Eigen::Index i = 0; i < y.size(); ++i) y[i] = pred[i] + rep.sigma / w[i] * gauss(rng);
        p.setMeasured(y);
        const SolverOutcome so = levenbergMarquardt(p, x, s, &sub.basis);
        for (int i = 0; i < n; ++i) samples[i].push_back(so.x[i] * p.layout()[i].scale);
    }
    p.setMeasured(Eigen::VectorXd());
    rep.monteCarloSamples = o.monteCarlo;
    for (int i = 0; i < n; ++i) {
        ParameterEstimate& e = rep.parameters[i];
        if (!e.identified) continue;
        std::vector<double>& v = samples[i];
        const double mean = std::accumulate(v.begin(), v.end(), 0.0) / v.size();
        double ss = 0;
        for (double a : v) ss += (a - mean) * (a - mean);
        e.mcStddev = v.size() > 1 ? std::sqrt(ss / (v.size() - 1)) : kNaN;
        std::sort(v.begin(), v.end());
        const auto quant = [&](double q) {
            const double pos = q * (v.size() - 1);
            const size_t k = static_cast<size_t>(std::floor(pos));
            const double f = pos - k;
            return k + 1 < v.size() ? v[k] * (1 - f) + v[k + 1] * f : v.back();
        };
        // Percentile interval of the estimate, re-centred on the estimate from the data.
        e.mcLower95 = e.value - (mean - quant(0.025));
        e.mcUpper95 = e.value + (quant(0.975) - mean);
    }
}

}  // namespace

void validateIdentifyOptions(const IdentifyOptions& options) {
    const SolverChoice& solver = options.solver;
    const bool nlopt = solver.kind == SolverKind::Nlopt;
    if (!nlopt && !solver.algorithm.empty())
        throw ModelError(fmt::format("solver: the algorithm '{}' belongs to NLopt, not to Levenberg-Marquardt",
                                     solver.algorithm));
    if (nlopt && !nloptAlgorithmKnown(solver.algorithm))
        throw ModelError(fmt::format("unknown NLopt algorithm '{}' (e.g. LD_LBFGS, LD_SLSQP, LN_BOBYQA, LN_SBPLX)",
                                     solver.algorithm));
    if (options.maxIterations <= 0) throw ModelError("the iteration limit must be positive");
    if (!(options.rankTolerance > 0 && options.rankTolerance < 1)) throw ModelError("rank tolerance must be in (0, 1)");
    if (options.monteCarlo < 0) throw ModelError("Monte Carlo sample count must not be negative");
    if (!nlopt && !options.bounds.empty()) throw ModelError("bounds need a bounded solver: --solver nlopt:<ALGORITHM>");
    for (const ParameterBound& b : options.bounds)
        if (!(b.lower <= b.upper)) throw ModelError(fmt::format("bound for '{}': lower exceeds upper", b.name));
}

IdentificationResult identify(const MachineModel& machine, const Observations& observations,
                              const IdentifyOptions& options) {
    validateIdentifyOptions(options);
    const SolverChoice& solver = options.solver;
    const bool nlopt = solver.kind == SolverKind::Nlopt;
    std::vector<int> devs = options.deviations;
    if (devs.empty())
        for (int i = 0; i < static_cast<int>(machine.deviations.size()); ++i) devs.push_back(i);
    const DeviationSet start = options.start ? *options.start : DeviationSet(machine);
    if (start.values.size() != machine.parameterCount())
        throw ModelError(fmt::format("starting deviation set does not fit machine '{}'", machine.name));
    const UnknownLayout layout(machine, devs, observations);
    LsqProblem problem(machine, observations, layout, start);
    const Eigen::VectorXd x0 = problem.start();
    const ObservableSubspace sub = observableSubspace(problem, options.rankTolerance);

    SolverOutcome so;
    if (nlopt) {
        Eigen::VectorXd lo, hi;
        boxBounds(layout, options, lo, hi);
        so = solveNlopt(problem, x0, solver.algorithm, lo, hi, 200 * options.maxIterations);
    } else {
        SolverSettings s;
        s.maxIterations = options.maxIterations;
        s.rankTolerance = options.rankTolerance;
        so = levenbergMarquardt(problem, x0, s, &sub.basis);
    }

    IdentificationResult res{problem.deviations(so.x), problem.nuisance(so.x), {}};
    IdentificationReport& rep = res.report;
    rep.machine = machine.name;
    rep.solver = nlopt ? "nlopt:" + solver.algorithm : "levenberg-marquardt";
    rep.termination = so.termination;
    rep.converged = so.converged;
    rep.iterations = so.iterations;
    rep.evaluations = so.evaluations;
    analyzeSolution(problem, sub, x0, so.x, options.rankTolerance, rep, so.jacobian.size() ? &so.jacobian : nullptr);
    if (!so.converged) rep.warnings.push_back("the solver did not converge: " + so.termination);
    if (!rep.unidentified.empty())
        rep.warnings.push_back(fmt::format("{} of {} unknowns are not identifiable from these measurements",
                                           rep.unidentified.size(), rep.unknowns));
    if (rep.dof <= 0) rep.warnings.push_back("no redundancy (observations ≤ rank): no uncertainty estimate");
    testAdequacy(problem, so.x, options, rep);  // the residual against the noise; its warning comes first

    // Present = estimated deviations with every coefficient identified; unidentified ones keep the start values.
    for (int di : devs) res.deviations.present[di] = 1;
    for (int i = 0; i < layout.size(); ++i) {
        const UnknownInfo& u = layout[i];
        if (u.nuisance || rep.parameters[i].identified) continue;
        if (machine.deviations[static_cast<size_t>(u.deviation)].kind == DeviationKind::Location)
            res.deviations.setIsoValue(u.deviation, start.isoValue(u.deviation));
        else
            res.deviations.values[u.flat] = start.values[u.flat];
    }
    for (int i = 0; i < layout.size(); ++i)
        if (!layout[i].nuisance && !rep.parameters[i].identified) res.deviations.present[layout[i].deviation] = 0;
    for (int i = 0; i < layout.size(); ++i) {
        const UnknownInfo& u = layout[i];
        if (u.nuisance || machine.deviations[static_cast<size_t>(u.deviation)].alias.empty()) continue;
        rep.parameters[i].aliasValue = res.deviations.aliasValue(u.deviation, u.flat - machine.deviations[static_cast<size_t>(u.deviation)].offset);
    }
    monteCarlo(problem, sub, so.x, options, rep);
    return res;
}

}  // namespace cnccomp::identification
