#include "cnccomp/pose_solver.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

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

/// Σ p[0 … K) as Eigen's unrolled reduction without packets sums it (redux_novec_unroller: the two halves, each summed
/// the same way).
template <int K>
inline double halvesSum(const double* p) {
    if constexpr (K == 1) return p[0];
    else return halvesSum<K / 2>(p) + halvesSum<K - K / 2>(p + K / 2);
}

/// The two lanes of the sum of P packets p[2i], p[2i + 1] (by halves).
template <int P>
inline void packetLanes(const double* p, double* lanes) {
    if constexpr (P == 1) {
        lanes[0] = p[0];
        lanes[1] = p[1];
    } else {
        double a[2], b[2];
        packetLanes<P / 2>(p, a);
        packetLanes<P - P / 2>(p + 2 * (P / 2), b);
        lanes[0] = a[0] + b[0];
        lanes[1] = a[1] + b[1];
    }
}

/// Σ p[0 … K) as Eigen's unrolled reduction with SSE2 packets of two sums it (redux_vec_unroller, then predux and the
/// odd last term): the packets summed by halves lane by lane, the two lanes added, then p[K − 1] when K is odd.
template <int K>
inline double packetSum(const double* p) {
    if constexpr (K == 1) {
        return p[0];
    } else {
        double lanes[2];
        packetLanes<K / 2>(p, lanes);
        const double s = lanes[0] + lanes[1];
        if constexpr (K % 2 == 1) return s + p[K - 1];
        else return s;
    }
}

/// Column c of A⁻¹ = L⁻ᵀ L⁻¹ e_c from the Cholesky factor (lower triangle of `llt`, column-major), with the arithmetic
/// of Eigen::LLT<Matrix<double, N, N>>::solveInPlace on e_c, operation for operation (to the bit: test
/// NormalFactor.FixedSizeInverseIsEigensLltSolveToTheBit), written out so that the values stay in registers: Eigen's
/// unrolled solve stores each xᵢ alone and reads the next sum's two at once (a load the processor cannot forward from
/// two smaller stores: it waits for them; most of the factorisation's time). Forward, L y = e_c: yᵢ = (e_c,ᵢ − Σⱼ Lᵢⱼ
/// yⱼ) / Lᵢᵢ, the row's sum without packets (a row is strided); yᵢ = +0 above c, as Eigen's 0 − (±0) / Lᵢᵢ gives, so
/// its divisions are skipped there. Backward, Lᵀ x = y: xᵢ = (yᵢ − Σⱼ Lⱼᵢ xⱼ) / Lᵢᵢ, the column's sum with packets.
template <int N>
inline void inverseColumn(const double* L, int c, double* x) {
    auto l = [L](int i, int j) { return L[i + N * j]; };
    for (int i = 0; i < N; ++i) x[i] = 0.0;
    x[c] = 1.0;
    [&]<int... I>(std::integer_sequence<int, I...>) {
        auto forward = [&]<int Row>(std::integral_constant<int, Row>) {
            if (Row < c) return;  // +0
            if constexpr (Row > 0) {
                double p[Row];
                for (int j = 0; j < Row; ++j) p[j] = l(Row, j) * x[j];
                x[Row] -= halvesSum<Row>(p);
            }
            x[Row] /= l(Row, Row);
        };
        (forward(std::integral_constant<int, I>{}), ...);
        auto backward = [&]<int Row>(std::integral_constant<int, Row>) {
            constexpr int K = N - 1 - Row;
            if constexpr (K > 0) {
                double p[K];
                for (int j = 0; j < K; ++j) p[j] = l(Row + 1 + j, Row) * x[Row + 1 + j];
                x[Row] -= packetSum<K>(p);
            }
            x[Row] /= l(Row, Row);
        };
        (backward(std::integral_constant<int, N - 1 - I>{}), ...);
    }(std::make_integer_sequence<int, N>{});
}

/// A⁻¹ of the symmetric positive definite A by Cholesky (Eigen::LLT), column by column (Eigen's solve with a matrix
/// right-hand side takes its blocked GEMM path, several times the instructions at these sizes; for a fixed N the
/// columns are solved by inverseColumn, Eigen's arithmetic written out). False when A is not positive definite or the
/// inverse is not finite.
template <int N>
bool invertFixed(const SmallMatrix& A, SmallMatrix& inverse) {
    using M = Eigen::Matrix<double, N, N, 0, N == Eigen::Dynamic ? kMaxAxes : N, N == Eigen::Dynamic ? kMaxAxes : N>;
    using V = Eigen::Matrix<double, N, 1, 0, N == Eigen::Dynamic ? kMaxAxes : N, 1>;
    const int n = static_cast<int>(A.rows());
    const M a = A;
    const Eigen::LLT<M> llt(a);
    if (llt.info() != Eigen::Success) return false;
    if constexpr (N != Eigen::Dynamic) {
        const double* L = llt.matrixLLT().data();
        for (int c = 0; c < N; ++c) {
            double x[N];
            inverseColumn<N>(L, c, x);
            for (int i = 0; i < N; ++i) inverse(i, c) = x[i];
        }
    } else {
        V e = V::Zero(n);
        for (int c = 0; c < n; ++c) {
            e.setZero();
            e[c] = 1.0;
            llt.solveInPlace(e);
            inverse.col(c) = e;
        }
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
