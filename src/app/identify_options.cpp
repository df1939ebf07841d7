#include "app/identify_options.hpp"

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/identification/nlopt_solver.hpp"
#include "cnccomp/io/text_util.hpp"

namespace cnccomp::app {
using namespace cnccomp::identification;
using namespace cnccomp::io;

Approach parseApproach(std::string_view t) {
    if (t == "least-squares" || t == "lsq") return Approach::LeastSquares;
    if (t == "formulas" || t == "closed-form") return Approach::Formulas;
    throw ModelError(fmt::format("unknown --method '{}' (least-squares, formulas)", t));
}

Observe parseObserve(std::string_view t) {
    if (t == "traces") return Observe::Traces;
    if (t == "eccentricity") return Observe::Eccentricity;
    throw ModelError(fmt::format("unknown --observe '{}' (traces, eccentricity)", t));
}

SolverChoice parseSolver(std::string_view t) {
    if (t == "lm" || t == "levenberg-marquardt") return {};
    if (t.starts_with("nlopt:") && t.size() > 6) return {SolverKind::Nlopt, std::string(t.substr(6))};
    throw ModelError(fmt::format("unknown --solver '{}' (lm, or nlopt:<ALGORITHM> such as nlopt:LD_LBFGS)", t));
}

std::string solverText(const SolverChoice& s) {
    return s.kind == SolverKind::Nlopt ? "nlopt:" + s.algorithm : std::string("lm");
}

namespace {

/// One item of --bounds as written: NAME=LOWER:UPPER (numbers in um or arcsec, the unit applied by parseBounds).
struct BoundItem {
    std::string item, name;
    double lo = 0, hi = 0;
};

/// The items of --bounds (comma-separated, empty items skipped); ModelError naming the item whose syntax is wrong.
/// The names are checked against the machine by parseBounds.
std::vector<BoundItem> boundItems(const std::string& text) {
    std::vector<BoundItem> out;
    for (const std::string& item : commaItems(text)) {
        const size_t eq = item.find('='), colon = item.find(':', eq == std::string::npos ? 0 : eq);
        if (eq == std::string::npos || colon == std::string::npos)
            throw ModelError(fmt::format("--bounds item '{}': expected NAME=LOWER:UPPER (um or arcsec)", item));
        const auto lo = parseNumber(trim(std::string_view(item).substr(eq + 1, colon - eq - 1)));
        const auto hi = parseNumber(trim(std::string_view(item).substr(colon + 1)));
        if (!lo || !hi) throw ModelError(fmt::format("--bounds item '{}': bounds must be numbers", item));
        out.push_back({item, std::string(trim(std::string_view(item).substr(0, eq))), *lo, *hi});
    }
    return out;
}

}  // namespace

void validateOptions(const IdentificationOptions& o) {
    const bool nlopt = o.solver.kind == SolverKind::Nlopt;
    if (nlopt && !nloptAlgorithmKnown(o.solver.algorithm))
        throw ModelError(fmt::format("--solver {}: unknown NLopt algorithm '{}' (e.g. LD_LBFGS, LD_SLSQP, LN_BOBYQA, "
                                     "LN_SBPLX)",
                                     solverText(o.solver), o.solver.algorithm));
    if (!nlopt && !o.solver.algorithm.empty())
        throw ModelError(fmt::format("--solver: the algorithm '{}' belongs to nlopt:<ALGORITHM>, not to lm",
                                     o.solver.algorithm));
    if (o.maxIterations <= 0)
        throw ModelError(fmt::format("--max-iterations {}: the iteration limit must be positive", o.maxIterations));
    if (!(o.rankTolerance > 0 && o.rankTolerance < 1))
        throw ModelError(fmt::format("--rank-tolerance {:g}: rank tolerance must be in (0, 1)", o.rankTolerance));
    if (o.monteCarlo < 0)
        throw ModelError(fmt::format("--monte-carlo {}: Monte Carlo sample count must not be negative", o.monteCarlo));
    if (o.refine > 20) throw ModelError("--refine takes 0..20 passes");
    (void)boundItems(o.bounds);  // the syntax, before any file is read
    // The formulas refuse every least-squares option with their own reason (the method's check).
    if (o.approach == Approach::LeastSquares && !o.bounds.empty() && !nlopt)
        throw ModelError("bounds need a bounded solver: --solver nlopt:<ALGORITHM>");
}

std::vector<ParameterBound> parseBounds(const MachineModel& m, const std::string& text) {
    std::vector<ParameterBound> out;
    for (const BoundItem& b : boundItems(text)) {
        const int di = m.deviationIndex(b.name.substr(0, b.name.find('[')));
        // Nuisance names ("run.xT") are lengths; deviations take their own unit.
        const double unit = di >= 0 && m.deviations[di].isAngle() ? kArcsec : kUm;
        if (di < 0 && b.name.find('.') == std::string::npos)
            throw ModelError(fmt::format("--bounds: unknown deviation '{}' for machine '{}'", b.name, m.name));
        if (!(b.lo <= b.hi)) throw ModelError(fmt::format("--bounds item '{}': lower exceeds upper", b.item));
        out.push_back({b.name, b.lo * unit, b.hi * unit});
    }
    return out;
}

}  // namespace cnccomp::app
