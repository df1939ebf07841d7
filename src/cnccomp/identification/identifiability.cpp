#include "cnccomp/identification/identifiability.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include <fmt/format.h>

#include "cnccomp/identification/levenberg_marquardt.hpp"

namespace cnccomp::identification {

double ParameterEstimate::displayScale() const { return angle ? kArcsec : kUm; }

int IdentificationReport::find(const std::string& nameOrAlias) const {
    for (size_t i = 0; i < parameters.size(); ++i)
        if (parameters[i].name == nameOrAlias || (!parameters[i].alias.empty() && parameters[i].alias == nameOrAlias))
            return static_cast<int>(i);
    return -1;
}

double normalQuantile(double p) {
    // Acklam's approximation, then one Newton–Halley refinement with erfc.
    static const double a[] = {-3.969683028665376e+01, 2.209460984245205e+02, -2.759285104469687e+02,
                               1.383577518672690e+02, -3.066479806614716e+01, 2.506628277459239e+00};
    static const double b[] = {-5.447609879822406e+01, 1.615858368580409e+02, -1.556989798598866e+02,
                               6.680131188771972e+01, -1.328068155288572e+01};
    static const double c[] = {-7.784894002430293e-03, -3.223964580411365e-01, -2.400758277161838e+00,
                               -2.549732539343734e+00, 4.374664141464968e+00, 2.938163982698783e+00};
    static const double d[] = {7.784695709041462e-03, 3.224671290700398e-01, 2.445134137142996e+00,
                               3.754408661907416e+00};
    if (!(p > 0 && p < 1)) return kNaN;
    double x;
    if (p < 0.02425) {
        const double q = std::sqrt(-2 * std::log(p));
        x = (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
            ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1);
    } else if (p <= 1 - 0.02425) {
        const double q = p - 0.5, r = q * q;
        x = (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * q /
            (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1);
    } else {
        const double q = std::sqrt(-2 * std::log(1 - p));
        x = -(((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
            ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1);
    }
    const double e = 0.5 * std::erfc(-x / std::sqrt(2.0)) - p;
    const double u = e * std::sqrt(2 * kPi) * std::exp(x * x / 2);
    return x - u / (1 + x * u / 2);
}

std::vector<int> coupledGroups(const Eigen::MatrixXd& P, const std::vector<char>& unidentified, double coupled, int& groups) {
    const int n = static_cast<int>(P.rows());
    std::vector<int> group(static_cast<size_t>(n), -1);
    groups = 0;
    for (int i = 0; i < n; ++i) {
        if (!unidentified[static_cast<size_t>(i)] || group[static_cast<size_t>(i)] >= 0) continue;
        std::vector<int> stack{i};
        group[static_cast<size_t>(i)] = groups;
        while (!stack.empty()) {
            const int a = stack.back();
            stack.pop_back();
            for (int b = 0; b < n; ++b)
                if (unidentified[static_cast<size_t>(b)] && group[static_cast<size_t>(b)] < 0 && std::abs(P(a, b)) > coupled) {
                    group[static_cast<size_t>(b)] = groups;
                    stack.push_back(b);
                }
        }
        ++groups;
    }
    return group;
}

double studentTQuantile(double p, int dof) {
    const double z = normalQuantile(p);
    if (dof <= 0) return kNaN;
    const double n = dof, z2 = z * z;
    // Cornish–Fisher expansion (Abramowitz & Stegun 26.7.5).
    return z + (z2 + 1) * z / (4 * n) + ((5 * z2 + 16) * z2 + 3) * z / (96 * n * n) +
           (((3 * z2 + 19) * z2 + 17) * z2 - 15) * z / (384 * n * n * n) +
           ((((79 * z2 + 776) * z2 + 1482) * z2 - 1920) * z2 - 945) * z / (92160 * n * n * n * n);
}

std::string formatCombination(const std::vector<std::string>& names, const std::vector<double>& coefficients) {
    std::string s;
    for (size_t i = 0; i < names.size(); ++i) {
        const double c = coefficients[i];
        if (i == 0) {
            s += c == 1.0 ? names[i] : c == -1.0 ? "-" + names[i] : fmt::format("{:.6g}·{}", c, names[i]);
            continue;
        }
        s += c < 0 ? " - " : " + ";
        const double a = std::abs(c);
        s += std::abs(a - 1.0) < 1e-12 ? names[i] : fmt::format("{:.6g}·{}", a, names[i]);
    }
    return s;
}

namespace {

/// Reduced row-echelon basis of the row space of A (rows × cols), pivots in column order.
Eigen::MatrixXd rowEchelon(Eigen::MatrixXd A, double tol) {
    const Eigen::Index rows = A.rows(), cols = A.cols();
    Eigen::Index r = 0;
    for (Eigen::Index c = 0; c < cols && r < rows; ++c) {
        Eigen::Index piv;
        const double best = A.col(c).segment(r, rows - r).cwiseAbs().maxCoeff(&piv);
        if (best <= tol) {
            A.col(c).segment(r, rows - r).setZero();
            continue;
        }
        piv += r;
        A.row(r).swap(A.row(piv));
        A.row(r) /= A(r, c);
        for (Eigen::Index i = 0; i < rows; ++i)
            if (i != r) A.row(i) -= A(i, c) * A.row(r);
        ++r;
    }
    return A.topRows(r);
}

}  // namespace

void analyzeSolution(const LsqProblem& p, const ObservableSubspace& sub, const Eigen::VectorXd& x0,
                     const Eigen::VectorXd& x, double rankTolerance, IdentificationReport& rep,
                     const Eigen::MatrixXd* jacobianAtX) {
    const UnknownLayout& L = p.layout();
    const int n = L.size(), m = p.rows();
    Eigen::VectorXd r, r0;
    p.residuals(x, r);
    p.residuals(x0, r0);
    Eigen::MatrixXd J;
    if (jacobianAtX && jacobianAtX->rows() == m && jacobianAtX->cols() == n) J = *jacobianAtX * sub.basis;
    else {
        p.jacobian(x, J);
        J = J * sub.basis;  // observable part at the solution
    }
    const JacobianSvd d = decomposeJacobian(J, rankTolerance);

    rep.observations = m;
    rep.unknowns = n;
    rep.rank = sub.rank;
    rep.rankTolerance = rankTolerance;
    rep.dof = m - sub.rank;
    rep.singularValues.assign(sub.singular.data(), sub.singular.data() + sub.singular.size());
    // Singular values are in (residual mm) per (solver unit); report them per µm of residual.
    for (double& s : rep.singularValues) s /= kUm;
    rep.conditionNumber = sub.rank > 0 ? sub.singular[0] / sub.singular[sub.rank - 1] : kNaN;
    rep.costBefore = 0.5 * r0.squaredNorm() / (kUm * kUm);
    rep.costAfter = 0.5 * r.squaredNorm() / (kUm * kUm);
    rep.sigma = rep.dof > 0 ? std::sqrt(r.squaredNorm() / rep.dof) : kNaN;

    // Per-run residuals (unweighted).
    rep.runs.clear();
    for (size_t k = 0; k < p.observations().size(); ++k) {
        const ObservationModel& o = *p.observations()[k];
        RunResidual rr;
        rr.run = o.runName();
        rr.kind = o.kind();
        rr.samples = o.size();
        const auto seg = r.segment(p.rowStart(static_cast<int>(k)), o.size()) / o.weight();
        const auto seg0 = r0.segment(p.rowStart(static_cast<int>(k)), o.size()) / o.weight();
        rr.rmsAfter = std::sqrt(seg.squaredNorm() / std::max(1, o.size()));
        rr.rmsBefore = std::sqrt(seg0.squaredNorm() / std::max(1, o.size()));
        rr.maxAfter = seg.cwiseAbs().maxCoeff();
        rep.runs.push_back(rr);
    }

    // Null space, unidentified parameters and their groups.
    const Eigen::MatrixXd& N = sub.null;
    const Eigen::MatrixXd P = N * N.transpose();  // projector on the unobservable directions
    constexpr double kCoupled = 1e-6;
    std::vector<char> unidentified(n, 0);
    for (int i = 0; i < n; ++i) unidentified[i] = P(i, i) > kCoupled;

    // Covariance (scaled), then internal units.
    Eigen::MatrixXd covS = Eigen::MatrixXd::Zero(n, n);
    const double s2 = rep.dof > 0 ? r.squaredNorm() / rep.dof : kNaN;
    {
        Eigen::MatrixXd covZ = Eigen::MatrixXd::Zero(sub.rank, sub.rank);
        for (int i = 0; i < d.rank; ++i) covZ += d.V.col(i) * d.V.col(i).transpose() / (d.singular[i] * d.singular[i]);
        covS = s2 * sub.basis * covZ * sub.basis.transpose();
        if (d.rank < sub.rank)
            rep.warnings.push_back("the Jacobian at the solution has lower rank than at the nominal machine");
    }
    Eigen::VectorXd scale(n);
    for (int i = 0; i < n; ++i) scale[i] = L[i].scale;
    rep.covariance = scale.asDiagonal() * covS * scale.asDiagonal();
    const double t = studentTQuantile(0.975, rep.dof);

    rep.parameters.clear();
    rep.unidentified.clear();
    for (int i = 0; i < n; ++i) {
        const UnknownInfo& u = L[i];
        ParameterEstimate e;
        e.name = u.name;
        e.alias = u.alias;
        e.nuisance = u.nuisance;
        e.angle = u.angle;
        e.start = x0[i] * u.scale;
        e.value = x[i] * u.scale;
        e.identified = !unidentified[i];
        if (e.identified) {
            e.stddev = std::sqrt(std::max(0.0, rep.covariance(i, i)));
            e.lower95 = e.value - t * e.stddev;
            e.upper95 = e.value + t * e.stddev;
        } else {
            rep.unidentified.push_back(u.name);
            rep.covariance.row(i).setConstant(kNaN);
            rep.covariance.col(i).setConstant(kNaN);
        }
        rep.parameters.push_back(e);
    }

    // Confounded groups: connected components of the coupling graph of P.
    rep.identifiable.clear();
    rep.unobservable.clear();
    int groups = 0;
    const std::vector<int> group = coupledGroups(P, unidentified, kCoupled, groups);
    for (int g = 0; g < groups; ++g) {
        std::vector<int> idx;
        for (int i = 0; i < n; ++i)
            if (group[i] == g) idx.push_back(i);
        const int k = static_cast<int>(idx.size());
        Eigen::MatrixXd Pg(k, k), Ng(k, N.cols());
        for (int a = 0; a < k; ++a) {
            Ng.row(a) = N.row(idx[a]);
            for (int b = 0; b < k; ++b) Pg(a, b) = P(idx[a], idx[b]);
        }
        const auto toCombination = [&](const Eigen::RowVectorXd& rowScaled, bool functional) {
            // Functional a·x_s = Σ (a_j / scale_j) x_j; direction δx_j = a_j · scale_j.
            Combination c;
            std::vector<double> coef;
            std::vector<int> who;
            for (int a = 0; a < k; ++a) {
                if (std::abs(rowScaled[a]) < 1e-9) continue;
                coef.push_back(functional ? rowScaled[a] / scale[idx[a]] : rowScaled[a] * scale[idx[a]]);
                who.push_back(idx[a]);
            }
            if (who.empty()) return c;
            const double lead = coef[0];
            Eigen::VectorXd b = Eigen::VectorXd::Zero(n);
            for (size_t j = 0; j < who.size(); ++j) {
                c.names.push_back(L[who[j]].name);
                c.coefficients.push_back(j == 0 ? 1.0 : coef[j] / lead);
                b[who[j]] = (j == 0 ? 1.0 : coef[j] / lead) * scale[who[j]];
            }
            c.text = formatCombination(c.names, c.coefficients);
            c.angle = L[who[0]].angle;
            if (functional) {
                c.value = b.dot(x);
                c.stddev = std::sqrt(std::max(0.0, b.dot(covS * b)));
            }
            return c;
        };
        const Eigen::MatrixXd comb = rowEchelon(Eigen::MatrixXd::Identity(k, k) - Pg, 1e-6);
        for (Eigen::Index row = 0; row < comb.rows(); ++row) {
            Combination c = toCombination(comb.row(row), true);
            if (!c.names.empty()) rep.identifiable.push_back(c);
        }
        const Eigen::MatrixXd dirs = rowEchelon(Ng.transpose(), 1e-6);
        for (Eigen::Index row = 0; row < dirs.rows(); ++row) {
            Combination c = toCombination(dirs.row(row), false);
            if (!c.names.empty()) rep.unobservable.push_back(c);
        }
    }
}

}  // namespace cnccomp::identification
