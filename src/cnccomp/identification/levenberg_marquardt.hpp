#pragma once
// Levenberg–Marquardt on the exact model (LsqProblem), in scaled unknowns. Each step solves the damped normal
// equations through a QR of the Jacobian and an SVD of its R factor, truncated at the rank tolerance. The
// unknowns may be restricted to an observable subspace x = x0 + S·z (ObservableSubspace): unobservable
// directions then never move (they stay at the starting values and are reported as unidentified).
// Damping update of Nielsen (1999): λ ← λ·max(1/3, 1 − (2ρ − 1)³) on success, λ ← λ·ν, ν ← 2ν on failure.
#include <string>

#include "cnccomp/identification/problem.hpp"

namespace cnccomp::identification {

struct SolverSettings {
    int maxIterations = 50;
    double rankTolerance = 1e-7;   ///< singular values below this × the largest are treated as zero
    double stepTolerance = 1e-10;  ///< stop when ‖δ‖ ≤ tol · (‖x‖ + tol) (scaled units)
    double costTolerance = 1e-14;  ///< stop when an accepted step lowers the cost by less than this fraction
};

struct SolverOutcome {
    Eigen::VectorXd x;             ///< scaled unknowns at the end
    double costBefore = 0, costAfter = 0;  ///< ½ Σ r² in internal units
    int iterations = 0, evaluations = 0;
    bool converged = false;
    std::string termination;
    Eigen::MatrixXd jacobian;      ///< full scaled Jacobian at x when the solver ended right after computing it, else empty
};

/// `subspace`: optional n × r matrix with orthonormal columns; the step is confined to its span.
SolverOutcome levenbergMarquardt(const LsqProblem& problem, const Eigen::VectorXd& x0, const SolverSettings& s,
                                 const Eigen::MatrixXd* subspace = nullptr);

/// Singular value decomposition of a tall Jacobian through its QR factor: J = Q·R, R = U·S·Vᵀ.
struct JacobianSvd {
    Eigen::VectorXd singular;      ///< descending
    Eigen::MatrixXd V;             ///< right singular vectors (columns)
    Eigen::VectorXd projected;     ///< Uᵀ·(Qᵀ r)ₙ for a residual vector (when given)
    int rank = 0;
};
JacobianSvd decomposeJacobian(const Eigen::MatrixXd& J, double rankTolerance, const Eigen::VectorXd* r = nullptr);

/// First-order (structural) identifiability: the SVD of the scaled Jacobian with every deviation at zero (the
/// nominal machine) and the nuisance parameters at their starting values. Products of small deviations give the
/// Jacobian at a non-zero point spurious singular values of the order of the deviations (1e-5 relative) that no
/// real measurement can use; the nominal linearisation has exact zeros there.
struct ObservableSubspace {
    Eigen::VectorXd singular;  ///< descending, scaled units
    Eigen::MatrixXd basis;     ///< n × rank: right singular vectors of the observable directions
    Eigen::MatrixXd null;      ///< n × (n − rank): unobservable directions
    int rank = 0;
};
ObservableSubspace observableSubspace(const LsqProblem& problem, double rankTolerance);

}  // namespace cnccomp::identification
