#include "cnccomp/pose_solver.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>

namespace cnccomp {

uint32_t rotaryAxes(const MachineModel& m, uint32_t free) {
    uint32_t mask = 0;
    for (int i = 0; i < m.axisCount(); ++i)
        if (m.axisLink(i).kind == AxisKind::Rotary && (free & (1u << i))) mask |= 1u << i;
    return mask;
}

namespace {

/// Eigen-decomposition of the fixed-size G (closed form, Eigen's computeDirect) into c.lambda / c.V.
template <int K>
void direct(const SmallMatrix& G, bool vectors, AxisConditioning& c) {
    const Eigen::Matrix<double, K, K> g = G;
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, K, K>> eig;
    eig.computeDirect(g, vectors ? Eigen::ComputeEigenvectors : Eigen::EigenvaluesOnly);
    c.lambda = eig.eigenvalues();
    if (vectors) c.V = eig.eigenvectors();
}

/// s = gain · r for n axes (fixed axes: 0), the sums in the order of DampedNormalFactor::step's damped loop; N > 0:
/// n = N known at compile time (the loops unrolled).
template <int N>
void gainStep(const GainMatrix& gain, const Eigen::Matrix<double, 6, 1>& r, uint32_t free, double* s, int n = N) {
    const int m = N > 0 ? N : n;
    for (int i = 0; i < m; ++i) {
        double v = 0;
        if (free & (1u << i))
            for (int j = 0; j < 6; ++j) v += gain(i, j) * r[j];
        s[i] = v;
    }
}

/// A⁻¹ of the symmetric positive definite A by Cholesky (Eigen::LLT), column by column (Eigen's solve with a matrix
/// right-hand side takes its blocked GEMM path, several times the instructions at these sizes). False when A is not
/// positive definite or the inverse is not finite.
template <int N>
bool invertFixed(const SmallMatrix& A, SmallMatrix& inverse) {
    using M = Eigen::Matrix<double, N, N, 0, N == Eigen::Dynamic ? kMaxAxes : N, N == Eigen::Dynamic ? kMaxAxes : N>;
    using V = Eigen::Matrix<double, N, 1, 0, N == Eigen::Dynamic ? kMaxAxes : N, 1>;
    const int n = static_cast<int>(A.rows());
    const M a = A;
    const Eigen::LLT<M> llt(a);
    if (llt.info() != Eigen::Success) return false;
    V e = V::Zero(n);
    for (int c = 0; c < n; ++c) {
        e.setZero();
        e[c] = 1.0;
        llt.solveInPlace(e);
        inverse.col(c) = e;
    }
    return allFinite(inverse);
}

}  // namespace

void AxisConditioning::compute(const PoseJacobian& J, uint32_t mask, double scale, bool vectors) {
    k = 0;
    for (int i = 0; i < J.cols(); ++i)
        if (mask & (1u << i)) axes[k++] = i;
    lambda.resize(k);
    if (k == 0) return;
    SmallMatrix G(k, k);
    for (int a = 0; a < k; ++a)
        for (int b = 0; b <= a; ++b)
            G(a, b) = G(b, a) = J.block<3, 1>(3, axes[a]).dot(J.block<3, 1>(3, axes[b])) * scale;
    if (k == 1) {
        lambda[0] = G(0, 0);
        if (vectors) V.setOnes(1, 1);
    } else if (k == 2) {
        direct<2>(G, vectors, *this);
    } else if (k == 3) {
        direct<3>(G, vectors, *this);
    } else {
        Eigen::SelfAdjointEigenSolver<SmallMatrix> eig(G, vectors ? Eigen::ComputeEigenvectors : Eigen::EigenvaluesOnly);
        lambda = eig.eigenvalues();
        if (vectors) V = eig.eigenvectors();
    }
}

double AxisConditioning::smallestSingularValue() const {
    return k == 0 ? 1.0 : std::sqrt(std::max(0.0, lambda[0]));
}

bool singularDamping(const SingularPosePolicy& policy, const AxisConditioning& c, int n, SmallMatrix& D) {
    if (c.k == 0 || !(policy.damping > 0)) return false;
    const double lam2 = policy.damping * policy.damping;
    D.setZero(n, n);
    if (!(policy.zone > 0)) {  // φ ≡ 1: Σ vᵢ vᵢᵀ = I
        for (int a = 0; a < c.k; ++a) D(c.axes[a], c.axes[a]) = lam2;
        return true;
    }
    bool any = false;
    for (int e = 0; e < c.k; ++e) {
        const double sigma = std::sqrt(std::max(0.0, c.lambda[e]));
        if (sigma >= policy.zone) continue;
        const double phi = (1.0 - sigma / policy.zone) * (1.0 - sigma / policy.zone);
        for (int a = 0; a < c.k; ++a)
            for (int b = 0; b < c.k; ++b) D(c.axes[a], c.axes[b]) += lam2 * phi * c.V(a, e) * c.V(b, e);
        any = true;
    }
    return any;
}

void normalMatrix(const PoseJacobian& J, SmallMatrix& JtJ) {
    const int n = static_cast<int>(J.cols());
    JtJ.resize(n, n);
    for (int i = 0; i < n; ++i)
        for (int j = 0; j <= i; ++j) JtJ(i, j) = JtJ(j, i) = J.col(i).dot(J.col(j));
}

bool DampedNormalFactor::factor(const PoseJacobian& J, const SmallMatrix& JtJ, const SmallMatrix* D, uint32_t free,
                                double ridge) {
    const int n = static_cast<int>(JtJ.rows());
    SmallMatrix A(n, n);
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
            const bool both = (free & (1u << i)) && (free & (1u << j));
            A(i, j) = both ? JtJ(i, j) + (D ? (*D)(i, j) : 0.0) : (i == j ? 1.0 : 0.0);
        }
    if (ridge != 0)
        for (int i = 0; i < n; ++i) A(i, i) += ridge * (1.0 + A(i, i));
    gain.resize(n, 6);
    inverse.resize(n, n);
    bool ok = false;
    switch (n) {  // fixed sizes: Eigen unrolls the factorisation and the triangular solves
        case 3: ok = invertFixed<3>(A, inverse); break;
        case 4: ok = invertFixed<4>(A, inverse); break;
        case 5: ok = invertFixed<5>(A, inverse); break;
        case 6: ok = invertFixed<6>(A, inverse); break;
        default: ok = invertFixed<Eigen::Dynamic>(A, inverse); break;
    }
    if (!ok) {  // not positive definite (NaN): no step, the solve reports non-convergence
        inverse.setZero();
        gain.setZero();
        return false;
    }
    for (int i = 0; i < n; ++i) {
        double v[6] = {0, 0, 0, 0, 0, 0};
        if (free & (1u << i))
            for (int j = 0; j < n; ++j) {
                const double a = inverse(i, j);
                for (int r = 0; r < 6; ++r) v[r] += a * J(r, j);
            }
        for (int r = 0; r < 6; ++r) gain(i, r) = v[r];
    }
    return true;
}

void DampedNormalFactor::step(const Eigen::Matrix<double, 6, 1>& r, const SmallMatrix* D, const AxisVector& offset,
                              uint32_t free, AxisVector& s) const {
    const int n = static_cast<int>(inverse.rows());
    double g[kMaxAxes];
    if (D)
        for (int i = 0; i < n; ++i) {
            double v = 0;
            for (int j = 0; j < n; ++j) v += (*D)(i, j) * offset[j];
            g[i] = v;
        }
    s.resize(n);
    if (!D) {  // the common case: the gain alone, unrolled for the usual axis counts (the same sums in the same order)
        switch (n) {
            case 5: gainStep<5>(gain, r, free, s.data()); return;
            case 6: gainStep<6>(gain, r, free, s.data()); return;
            case 4: gainStep<4>(gain, r, free, s.data()); return;
            default: gainStep<0>(gain, r, free, s.data(), n); return;
        }
    }
    for (int i = 0; i < n; ++i) {  // damped: the gain's sum less A⁻¹ D (q − ref)
        double v = 0;
        if (free & (1u << i)) {
            for (int j = 0; j < 6; ++j) v += gain(i, j) * r[j];
            for (int j = 0; j < n; ++j) v -= inverse(i, j) * g[j];
        }
        s[i] = v;
    }
}

}  // namespace cnccomp
