#include "cnccomp/identification/levenberg_marquardt.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/QR>
#include <Eigen/SVD>

namespace cnccomp::identification {

JacobianSvd decomposeJacobian(const Eigen::MatrixXd& J, double rankTolerance, const Eigen::VectorXd* r) {
    const Eigen::Index m = J.rows(), n = J.cols();
    JacobianSvd out;
    if (n == 0) {  // no unknown the measurements can see (an empty observable subspace): rank 0, nothing to decompose
        out.singular = Eigen::VectorXd::Zero(0);
        out.V = Eigen::MatrixXd::Zero(0, 0);
        if (r) out.projected = Eigen::VectorXd::Zero(0);
        return out;
    }
    Eigen::MatrixXd R;
    Eigen::VectorXd g;
    if (m > n) {
        Eigen::HouseholderQR<Eigen::MatrixXd> qr(J);
        R = qr.matrixQR().topRows(n).triangularView<Eigen::Upper>();
        if (r) g = (qr.householderQ().transpose() * (*r)).head(n);
    } else {
        R = J;
        if (r) g = *r;
    }
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(R, Eigen::ComputeFullU | Eigen::ComputeFullV);
    out.singular = Eigen::VectorXd::Zero(n);
    out.singular.head(svd.singularValues().size()) = svd.singularValues();
    out.V = svd.matrixV();
    if (r) {
        out.projected = Eigen::VectorXd::Zero(n);
        out.projected.head(svd.matrixU().cols()) = svd.matrixU().transpose() * g;
    }
    const double smax = n > 0 ? out.singular[0] : 0.0;
    for (Eigen::Index i = 0; i < n; ++i)
        if (out.singular[i] > rankTolerance * smax && out.singular[i] > 0) ++out.rank;
    return out;
}

ObservableSubspace observableSubspace(const LsqProblem& p, double rankTolerance) {
    const LsqProblem nominal(p.layout().machine(), p.observations(), p.layout(), DeviationSet(p.layout().machine()));
    Eigen::VectorXd x = nominal.start();  // deviations zero, nuisance at the starting values
    x.head(p.layout().deviationUnknowns()).setZero();
    Eigen::MatrixXd J;
    nominal.jacobian(x, J);
    const JacobianSvd d = decomposeJacobian(J, rankTolerance);
    ObservableSubspace o;
    o.singular = d.singular;
    o.rank = d.rank;
    o.basis = d.V.leftCols(d.rank);
    o.null = d.V.rightCols(d.V.cols() - d.rank);
    return o;
}

SolverOutcome levenbergMarquardt(const LsqProblem& p, const Eigen::VectorXd& x0, const SolverSettings& s,
                                 const Eigen::MatrixXd* subspace) {
    SolverOutcome o;
    o.x = x0;
    Eigen::VectorXd r, rn, xn;
    p.residuals(o.x, r);
    ++o.evaluations;
    double cost = 0.5 * r.squaredNorm();
    o.costBefore = cost;
    Eigen::MatrixXd J, Jfull;
    double lambda = -1, nu = 2;
    o.termination = "maximum number of iterations reached";
    for (o.iterations = 0; o.iterations < s.maxIterations;) {
        if (cost == 0.0) {
            o.converged = true;
            o.termination = "zero residual";
            break;
        }
        p.jacobian(o.x, Jfull);
        J = subspace ? Eigen::MatrixXd(Jfull * (*subspace)) : Jfull;
        const JacobianSvd d = decomposeJacobian(J, s.rankTolerance, &r);
        ++o.iterations;
        if (d.rank == 0) {
            o.termination = "the measurements see none of the unknowns";
            break;
        }
        if (lambda < 0) lambda = 1e-8 * d.singular[0] * d.singular[0];  // near Gauss–Newton: the problems are mildly nonlinear
        bool accepted = false, done = false;
        for (int tries = 0; tries < 30 && !accepted; ++tries) {
            // δ = −Σ V_i s_i c_i / (s_i² + λ), with c = Uᵀ Qᵀ r (residual r, Jacobian of r).
            Eigen::VectorXd coef = Eigen::VectorXd::Zero(d.V.cols());
            double predicted = 0;  // model decrease ½|r|² − ½|r + Jδ|², in the SVD frame
            for (int i = 0; i < d.rank; ++i) {
                const double si = d.singular[i], ci = d.projected[i];
                const double a = -si * ci / (si * si + lambda);  // step coordinate along V_i
                coef[i] = a;
                predicted -= 0.5 * ((ci + si * a) * (ci + si * a) - ci * ci);
            }
            const Eigen::VectorXd delta = subspace ? Eigen::VectorXd(*subspace * (d.V * coef)) : Eigen::VectorXd(d.V * coef);
            const double stepNorm = delta.norm();
            if (stepNorm <= s.stepTolerance * (o.x.norm() + s.stepTolerance)) {
                o.converged = true;
                o.termination = "converged: step below tolerance";
                o.jacobian = std::move(Jfull);  // x has not moved since
                done = true;
                break;
            }
            xn = o.x + delta;
            p.residuals(xn, rn);
            ++o.evaluations;
            const double costNew = 0.5 * rn.squaredNorm();
            const double rho = predicted > 0 ? (cost - costNew) / predicted : -1;
            if (rho > 0 && std::isfinite(costNew)) {
                const double decrease = (cost - costNew) / cost;
                o.x = xn;
                r = rn;
                cost = costNew;
                lambda *= std::max(1.0 / 3.0, 1.0 - std::pow(2 * rho - 1, 3));
                nu = 2;
                accepted = true;
                if (decrease < s.costTolerance) {
                    o.converged = true;
                    o.termination = "converged: cost change below tolerance";
                    done = true;
                }
            } else {
                lambda *= nu;
                nu *= 2;
            }
        }
        if (done) break;
        if (!accepted) {
            o.converged = true;  // no direction lowers the cost: a (numerically) stationary point
            o.termination = "converged: no further decrease possible";
            break;
        }
    }
    o.costAfter = cost;
    return o;
}

}  // namespace cnccomp::identification
