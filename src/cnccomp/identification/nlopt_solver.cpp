#include "cnccomp/identification/nlopt_solver.hpp"

#include <nlopt.hpp>

#include <fmt/format.h>

#include "cnccomp/error.hpp"

namespace cnccomp::identification {

namespace {
struct Context {
    const LsqProblem* problem;
    Eigen::VectorXd r;
    Eigen::MatrixXd J;
    int evaluations = 0;
    double scale = 1;  ///< objective in µm² so that NLopt's tolerances see sensible numbers
};

double objective(unsigned n, const double* x, double* grad, void* data) {
    auto& c = *static_cast<Context*>(data);
    const Eigen::Map<const Eigen::VectorXd> xv(x, n);
    c.problem->residuals(xv, c.r);
    ++c.evaluations;
    if (grad) {
        c.problem->jacobian(xv, c.J);
        Eigen::Map<Eigen::VectorXd>(grad, n) = c.scale * (c.J.transpose() * c.r);
    }
    return 0.5 * c.scale * c.r.squaredNorm();
}

std::string resultName(nlopt::result r) {
    switch (r) {
        case nlopt::SUCCESS: return "success";
        case nlopt::STOPVAL_REACHED: return "stop value reached";
        case nlopt::FTOL_REACHED: return "converged: relative cost change below tolerance";
        case nlopt::XTOL_REACHED: return "converged: step below tolerance";
        case nlopt::MAXEVAL_REACHED: return "maximum number of evaluations reached";
        case nlopt::MAXTIME_REACHED: return "maximum time reached";
        default: return fmt::format("nlopt result {}", static_cast<int>(r));
    }
}
}  // namespace

bool nloptAlgorithmKnown(const std::string& algorithm) {
    return static_cast<int>(nlopt_algorithm_from_string(algorithm.c_str())) >= 0;
}

SolverOutcome solveNlopt(const LsqProblem& problem, const Eigen::VectorXd& x0, const std::string& algorithm,
                         const Eigen::VectorXd& lower, const Eigen::VectorXd& upper, int maxEvaluations) {
    const nlopt_algorithm a = nlopt_algorithm_from_string(algorithm.c_str());
    if (static_cast<int>(a) < 0)
        throw ModelError(fmt::format("unknown NLopt algorithm '{}' (e.g. LD_LBFGS, LD_SLSQP, LN_BOBYQA, LN_SBPLX)",
                                     algorithm));
    const unsigned n = static_cast<unsigned>(x0.size());
    nlopt::opt opt(static_cast<nlopt::algorithm>(a), n);
    Context c{&problem, {}, {}, 0, 1.0 / (kUm * kUm)};
    std::vector<double> lo(lower.data(), lower.data() + n), hi(upper.data(), upper.data() + n);
    std::vector<double> x(x0.data(), x0.data() + n);
    for (unsigned i = 0; i < n; ++i) x[i] = std::clamp(x[i], lo[i], hi[i]);
    SolverOutcome o;
    {
        Eigen::VectorXd r;
        problem.residuals(x0, r);
        o.costBefore = 0.5 * r.squaredNorm();
    }
    try {
        opt.set_lower_bounds(lo);
        opt.set_upper_bounds(hi);
        opt.set_min_objective(objective, &c);
        opt.set_xtol_rel(1e-12);
        opt.set_ftol_rel(1e-15);
        opt.set_maxeval(maxEvaluations);
        double f = 0;
        const nlopt::result res = opt.optimize(x, f);
        o.converged = res > 0 && res != nlopt::MAXEVAL_REACHED && res != nlopt::MAXTIME_REACHED;
        o.termination = resultName(res);
    } catch (const nlopt::roundoff_limited&) {
        o.converged = true;  // result is as good as the floating-point arithmetic allows
        o.termination = "converged: round-off limited";
    } catch (const std::invalid_argument& e) {
        throw ModelError(fmt::format("NLopt {} rejected the problem: {}", algorithm, e.what()));
    } catch (const std::exception& e) {
        o.converged = false;
        o.termination = fmt::format("NLopt failure: {}", e.what());
    }
    o.x = Eigen::Map<Eigen::VectorXd>(x.data(), n);
    Eigen::VectorXd r;
    problem.residuals(o.x, r);
    o.costAfter = 0.5 * r.squaredNorm();
    o.evaluations = c.evaluations;
    o.iterations = c.evaluations;
    return o;
}

}  // namespace cnccomp::identification
