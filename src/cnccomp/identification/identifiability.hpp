#pragma once
// Identifiability and uncertainty at a least-squares solution, from the SVD of the scaled Jacobian J = U S Vᵀ
// of the nominal machine (first-order identifiability, see ObservableSubspace):
//  - rank = number of singular values above rankTolerance · s_max; the remaining right singular vectors span
//    the directions the measurements cannot see (null space N);
//  - a parameter with a component in N is unidentified; parameters coupled through the projector N Nᵀ form
//    a confounded group, whose identifiable combinations span the complement of N within the group (reported
//    in reduced row-echelon form with deviation names, e.g. "EX0C + 360·EB0B");
//  - covariance from the residuals and the Jacobian at the solution restricted to the observable subspace B:
//    σ̂² = Σ r² / (m − rank), Cov = σ̂² B (Bᵀ Jᵀ J B)⁻¹ Bᵀ (scaled, then to internal units);
//    95 % intervals x̂ ± t(0.975, m − rank) · σ_i.
#include "cnccomp/identification/levenberg_marquardt.hpp"
#include "cnccomp/identification/problem.hpp"
#include "cnccomp/identification/report.hpp"

namespace cnccomp::identification {

/// Fills rank, singular values, condition number, parameters (values, identified flags, intervals), combinations,
/// covariance, σ̂, dof and the per-run residuals of `report` at scaled point x (start x0 for "before").
/// `jacobianAtX`: the scaled Jacobian at x when the caller has it (else it is computed).
void analyzeSolution(const LsqProblem& problem, const ObservableSubspace& subspace, const Eigen::VectorXd& x0,
                     const Eigen::VectorXd& x, double rankTolerance, IdentificationReport& report,
                     const Eigen::MatrixXd* jacobianAtX = nullptr);

/// Quantile of Student's t distribution (Cornish–Fisher expansion around the normal; exact enough for dof ≥ 3,
/// normal quantile for large dof). p in (0, 1).
/// Confounded groups: the connected components of the coupling graph of the null-space projector P among the
/// unidentified parameters (a and b are coupled when |P(a, b)| > coupled). Returns each parameter's group index, −1 for
/// the identified ones; `groups` receives the number of groups.
std::vector<int> coupledGroups(const Eigen::MatrixXd& P, const std::vector<char>& unidentified, double coupled, int& groups);

double studentTQuantile(double p, int dof);
/// Quantile of the standard normal distribution (Acklam's rational approximation refined by one Newton step).
double normalQuantile(double p);

/// "EX0C + 360·EB0B" from names and coefficients (first coefficient 1).
std::string formatCombination(const std::vector<std::string>& names, const std::vector<double>& coefficients);

}  // namespace cnccomp::identification
