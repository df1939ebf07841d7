// The factorised normal matrix of the damped Gauss–Newton step (DampedNormalFactor, pose_solver.hpp): its inverse and
// gain against an independent solve (Eigen's full-pivoting LU of the same A = JᵀJ + D with identity rows and columns
// for fixed axes, written out from its definition), for every axis count the solvers meet (the fixed sizes 3–6 and
// the generic 1, 2, 7–9), with and without damping and fixed axes; for the fixed sizes, the inverse bit for bit against
// Eigen's own LLT solve (the columns are its arithmetic written out); and the refusal of a matrix that is not positive
// definite (no step rather than a wrong one).
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <random>

#include <Eigen/Cholesky>
#include <Eigen/LU>

#include "cnccomp/pose_solver.hpp"

namespace cnccomp {
namespace {

/// A of DampedNormalFactor::factor written out from its definition (ridge 0).
Eigen::MatrixXd normalOf(const PoseJacobian& J, const SmallMatrix* D, uint32_t free) {
    const int n = static_cast<int>(J.cols());
    Eigen::MatrixXd A = Eigen::MatrixXd::Identity(n, n);
    const Eigen::MatrixXd JtJ = J.transpose() * J;
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j)
            if ((free & (1u << i)) && (free & (1u << j))) A(i, j) = JtJ(i, j) + (D ? (*D)(i, j) : 0.0);
    return A;
}

TEST(NormalFactor, InverseAndGainAgreeWithAnLuSolveForEveryAxisCount) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    int checked = 0;
    for (int n = 1; n <= kMaxAxes; ++n)
        for (int variant = 0; variant < 4; ++variant) {
            // Columns of the size of a tool point's (mm, up to ~500 mm lever arms) and tool axis' (weighted) derivatives.
            PoseJacobian J(6, n);
            for (int r = 0; r < 6; ++r)
                for (int c = 0; c < n; ++c) J(r, c) = (r < 3 ? 300.0 : 100.0) * u(rng);
            const uint32_t all = (1u << n) - 1u;
            const uint32_t free = ((variant & 1) && n > 1) ? all & ~(1u << (n / 2)) : all;
            SmallMatrix D;
            const bool damped = (variant & 2) != 0 || n > 6;  // 6 rows: JᵀJ alone is singular above 6 axes
            if (damped) {
                SmallMatrix B(n, n);
                for (int i = 0; i < n; ++i)
                    for (int j = 0; j < n; ++j) B(i, j) = u(rng);
                D = 25.0 * B * B.transpose();  // positive semi-definite, as singularDamping's
            }
            SmallMatrix JtJ;
            normalMatrix(J, JtJ);
            DampedNormalFactor f;
            ASSERT_TRUE(f.factor(J, JtJ, damped ? &D : nullptr, free, 0.0)) << "n " << n;
            const Eigen::MatrixXd A = normalOf(J, damped ? &D : nullptr, free);
            const Eigen::FullPivLU<Eigen::MatrixXd> lu(A);
            const Eigen::MatrixXd inv = lu.inverse();
            const double scale = inv.cwiseAbs().maxCoeff();
            EXPECT_LE((Eigen::MatrixXd(f.inverse) - inv).cwiseAbs().maxCoeff(), 1e-12 * scale) << "n " << n;
            // gain = A⁻¹ Jᵀ with zero rows for fixed axes.
            Eigen::MatrixXd gain = inv * J.transpose();
            for (int i = 0; i < n; ++i)
                if (!(free & (1u << i))) gain.row(i).setZero();
            EXPECT_LE((Eigen::MatrixXd(f.gain) - gain).cwiseAbs().maxCoeff(), 1e-12 * gain.cwiseAbs().maxCoeff() + 1e-300)
                << "n " << n;
            ++checked;
        }
    EXPECT_EQ(checked, 4 * kMaxAxes);
}

/// For the fixed sizes the inverse's columns are Eigen::LLT's solveInPlace on the unit vectors written out (registers
/// instead of Eigen's stores and reloads); the bits must stay Eigen's: random positive definite matrices (Jacobian
/// entries of magnitudes 2⁻⁹ … 2⁹, damped every other time) against Eigen's own fixed-size LLT, every entry of every
/// one compared bit for bit.
TEST(NormalFactor, FixedSizeInverseIsEigensLltSolveToTheBit) {
    std::mt19937_64 rng(20261128);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::uniform_int_distribution<int> e(-3, 3);
    auto check = [&]<int N>(std::integral_constant<int, N>) {
        int differ = 0;
        for (int k = 0; k < 20000; ++k) {
            PoseJacobian J(6, N);
            for (int r = 0; r < 6; ++r)
                for (int c = 0; c < N; ++c) J(r, c) = std::ldexp(u(rng), 3 * e(rng));
            SmallMatrix JtJ;
            normalMatrix(J, JtJ);
            SmallMatrix B(N, N);
            for (int i = 0; i < N; ++i)
                for (int j = 0; j < N; ++j) B(i, j) = u(rng);
            const SmallMatrix D = B * B.transpose();  // positive semi-definite, as singularDamping's
            const bool damped = k % 2 == 1;
            DampedNormalFactor f;
            ASSERT_TRUE(f.factor(J, JtJ, damped ? &D : nullptr, (1u << N) - 1u, 1e-12))
                << "N " << N << ", matrix " << k;
            Eigen::Matrix<double, N, N> A = JtJ;
            if (damped) A += D;
            for (int i = 0; i < N; ++i) A(i, i) += 1e-12 * (1.0 + A(i, i));
            const Eigen::LLT<Eigen::Matrix<double, N, N>> llt(A);
            for (int c = 0; c < N; ++c) {
                Eigen::Matrix<double, N, 1> x = Eigen::Matrix<double, N, 1>::Zero();
                x[c] = 1.0;
                llt.solveInPlace(x);
                for (int i = 0; i < N; ++i)
                    differ += std::bit_cast<uint64_t>(x[i]) != std::bit_cast<uint64_t>(f.inverse(i, c));
            }
        }
        EXPECT_EQ(differ, 0) << "N " << N;
    };
    check(std::integral_constant<int, 3>{});
    check(std::integral_constant<int, 4>{});
    check(std::integral_constant<int, 5>{});
    check(std::integral_constant<int, 6>{});
}

TEST(NormalFactor, RefusesAMatrixThatIsNotPositiveDefinite) {
    for (int n : {2, 5, 7}) {
        PoseJacobian J = PoseJacobian::Zero(6, n);
        for (int c = 0; c < n; ++c) J(c % 6, c) = 1.0;
        J.col(n - 1) = J.col(0);  // two equal columns: JᵀJ singular (no ridge)
        SmallMatrix JtJ;
        normalMatrix(J, JtJ);
        DampedNormalFactor f;
        EXPECT_FALSE(f.factor(J, JtJ, nullptr, (1u << n) - 1u, 0.0)) << "n " << n;
        EXPECT_EQ(f.inverse.cwiseAbs().maxCoeff(), 0.0) << "no step from a refused factorisation";
        EXPECT_EQ(f.gain.cwiseAbs().maxCoeff(), 0.0);
        // The ridge makes it factorisable.
        EXPECT_TRUE(f.factor(J, JtJ, nullptr, (1u << n) - 1u, 1e-12)) << "n " << n;
        J(0, 0) = std::nan("");
        normalMatrix(J, JtJ);
        EXPECT_FALSE(f.factor(J, JtJ, nullptr, (1u << n) - 1u, 1e-12)) << "n " << n << ": a NaN";
    }
}

}  // namespace
}  // namespace cnccomp
