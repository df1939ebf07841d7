#pragma once
// The options of an identification (the library façade src/app/identify.hpp; `cnccomp identify` fills them from its
// command line): typed, and checked as a whole before any measurement is read, as Ceres checks its
// Solver::Options with IsValid() before it solves (ceres-solver, include/ceres/solver.h). Text such as "nlopt:LD_SLSQP"
// or "formulas" is parsed here, at the edge; the core takes the enums (identification/lsq.hpp SolverChoice).
#include <string>
#include <string_view>
#include <vector>

#include "cnccomp/identification/lsq.hpp"
#include "cnccomp/machine.hpp"

namespace cnccomp::app {

/// How the deviations are found: least squares on the exact model (the most accurate) or the formulas of the paper
/// the measurement comes from.
enum class Approach { LeastSquares, Formulas };

/// What least squares fits on ball-bar runs: every raw sample, or the fitted circle centres.
enum class Observe { Traces, Eccentricity };

struct IdentificationOptions {
    Approach approach = Approach::LeastSquares;
    std::string measure;          ///< what the plan measures, overriding its runs' kinds (planMethodName; "" = classify)
    std::string traces;           ///< folder of the measured runs, one <run>.csv per run ("" = none)
    std::string eccentricities;   ///< ball-bar formulas: eccentricity CSV instead of traces and plan
    std::string probeLog = "cnccomp-probe.txt";  ///< sphere plans: the probe result file in the traces folder
    int refine = -1;              ///< formulas: refinement passes 0..20 (-1 = the method's default)
    std::string params;           ///< least squares: deviations to identify ("" = the method's default; "all")
    Observe observe = Observe::Traces;
    identification::SolverChoice solver;          ///< least squares: Levenberg-Marquardt (default) or NLopt
    std::string bounds;           ///< NLopt: "NAME=LOWER:UPPER, …" in µm / arcsec
    std::string start;            ///< least squares: deviation CSV with starting values ("" = zero)
    int monteCarlo = 0;           ///< resampled solutions for sampled intervals (0 = none)
    int maxIterations = 50;       ///< least squares: iteration limit
    unsigned long seed = 1;       ///< Monte Carlo random seed
    double rankTolerance = 1e-7;  ///< relative singular value below which a direction counts as unobservable
    std::string outer, inner;     ///< rotary axes of a cradle ("" = the machine's workpiece-side pair)
    std::string volumetricRun;    ///< R-test location: run to compare measured and modelled displacements
    bool components = false;      ///< DBB5: also the component errors of the table axis from its on-axis runs
    bool oneStage = false;        ///< least squares: one fit of every run (no stage for the linear-axis runs)
};

/// "least-squares" (or "lsq"), "formulas" (or "closed-form"). ModelError naming --method and the accepted values.
Approach parseApproach(std::string_view text);
/// "traces", "eccentricity". ModelError naming --observe and the accepted values.
Observe parseObserve(std::string_view text);
/// "lm" (or "levenberg-marquardt"), "nlopt:<ALGORITHM>" (e.g. nlopt:LD_SLSQP; the algorithm is checked by
/// validateOptions). ModelError naming --solver and the accepted values.
identification::SolverChoice parseSolver(std::string_view text);
/// The solver as parseSolver reads it: "lm" or "nlopt:<ALGORITHM>".
std::string solverText(const identification::SolverChoice& solver);

/// Checks every option that needs no file: the solver and its NLopt algorithm, the iteration limit, the rank
/// tolerance, the Monte Carlo count, --refine, the bounds' syntax and, for least squares, bounds only with a bounded
/// solver. ModelError naming the option and what it accepts. The façade calls it first; `cnccomp identify` calls it
/// before it reads the machine.
void validateOptions(const IdentificationOptions& options);

/// The bounds "NAME=LOWER:UPPER, …" (µm for lengths and nuisance parameters, arcsec for angles) in internal units,
/// the names checked against the machine. ModelError naming --bounds.
std::vector<identification::ParameterBound> parseBounds(const MachineModel& machine, const std::string& text);

}  // namespace cnccomp::app
