#pragma once
// General least-squares identification: any subset of a machine's deviations (location errors,
// squareness, spindle offsets, component-error coefficients) from any observations (ball-bar ΔL samples,
// R-test displacements, …) on the exact kinematic model, with the runs' nuisance parameters.
// Levenberg–Marquardt by default, NLopt as an alternative for bounded problems; the result carries a report
// with identifiability (named confounded combinations), covariance, 95 % intervals and optional Monte Carlo.
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "cnccomp/identification/observation.hpp"
#include "cnccomp/identification/report.hpp"

namespace cnccomp::identification {

/// Bounds of one unknown for bounded solvers, internal units.
struct ParameterBound {
    std::string name;  ///< ISO name, alias, "NAME[k]" or nuisance name
    double lower = -std::numeric_limits<double>::infinity(), upper = std::numeric_limits<double>::infinity();
};

/// The solver that minimises the cost. Typed: text such as "nlopt:LD_SLSQP" is parsed where the user gives it (the
/// application layer's identification options, src/app/identify_options.hpp), never here.
enum class SolverKind {
    LevenbergMarquardt,  ///< levenberg_marquardt.hpp (the default)
    Nlopt,               ///< nlopt_solver.hpp, bounded; `algorithm` names the NLopt algorithm
};

struct SolverChoice {
    SolverKind kind = SolverKind::LevenbergMarquardt;
    std::string algorithm;  ///< NLopt: the algorithm's name without the NLOPT_ prefix, e.g. LD_SLSQP; else empty
    bool operator==(const SolverChoice&) const = default;
};

struct IdentifyOptions {
    std::vector<int> deviations;        ///< indices into machine.deviations; empty = every deviation
    SolverChoice solver;                ///< Levenberg–Marquardt, or NLopt with an algorithm (e.g. LD_LBFGS)
    int maxIterations = 50;             ///< LM iterations (NLopt: ×200 evaluations)
    double rankTolerance = 1e-7;        ///< relative singular value below which a direction is unobservable
    std::vector<ParameterBound> bounds; ///< NLopt only
    double defaultBoundDisplay = 1000;  ///< NLopt: ± this many µm / arcsec for unknowns without a bound
    int monteCarlo = 0;                 ///< number of resampled solutions (0 = none)
    std::uint64_t seed = 1;             ///< Monte Carlo random seed
    std::optional<DeviationSet> start;  ///< starting values; deviations not estimated keep these values
    double statedNoise = std::numeric_limits<double>::quiet_NaN();  ///< instrument noise, mm (plan noise-um)
    std::string componentOption = "--params all";  ///< the option named when component errors seem missing
    bool staged = true;                 ///< identifyStaged(): fit what the linear-axis runs determine first
};

struct IdentificationResult {
    DeviationSet deviations;       ///< identified values; `present` marks the identified estimated deviations
    Eigen::VectorXd nuisance;      ///< nuisance parameters, internal units, in report order
    IdentificationReport report;
};

/// Checks the options alone, before any measurement is read (Ceres' Solver::Options::IsValid): the solver and its NLopt
/// algorithm, the iteration limit, the rank tolerance, the Monte Carlo count, bounds only with a bounded solver and
/// lower ≤ upper. ModelError naming the option. identify() calls it first.
void validateIdentifyOptions(const IdentifyOptions& options);

/// Throws ModelError for an empty observation list, an unknown solver or bound name, or bad options.
IdentificationResult identify(const MachineModel& machine, const Observations& observations,
                              const IdentifyOptions& options = {});

}  // namespace cnccomp::identification
