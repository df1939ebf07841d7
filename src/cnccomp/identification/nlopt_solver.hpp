#pragma once
// NLopt as an alternative solver for bounded problems: minimises ½‖r(x)‖² in scaled unknowns within box
// bounds, with the analytic gradient Jᵀr for gradient-based algorithms (LD_*), derivative-free otherwise.
#include <string>

#include "cnccomp/identification/levenberg_marquardt.hpp"

namespace cnccomp::identification {

/// Whether NLopt knows the algorithm name (without prefix), e.g. "LD_SLSQP".
bool nloptAlgorithmKnown(const std::string& algorithm);

/// `algorithm`: NLopt name without prefix, e.g. "LD_LBFGS", "LN_BOBYQA", "LD_SLSQP". lower/upper: scaled.
/// Throws ModelError for an unknown algorithm name.
SolverOutcome solveNlopt(const LsqProblem& problem, const Eigen::VectorXd& x0, const std::string& algorithm,
                         const Eigen::VectorXd& lower, const Eigen::VectorXd& upper, int maxEvaluations);

}  // namespace cnccomp::identification
