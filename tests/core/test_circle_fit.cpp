// Least-squares circle fit (Gander et al. 1994): exact circles, partial arcs, finite-difference Jacobian.
#include <gtest/gtest.h>

#include <random>

#include "cnccomp/circle_fit.hpp"
#include "cnccomp/error.hpp"
#include "cnccomp/geometry.hpp"

namespace cnccomp {
namespace {

std::vector<Eigen::Vector2d> arc(Eigen::Vector2d c, double r, double from, double to, int n) {
    std::vector<Eigen::Vector2d> p;
    for (int i = 0; i < n; ++i) {
        const double a = from + (to - from) * i / (n - 1);
        p.push_back(c + r * Eigen::Vector2d(std::cos(a), std::sin(a)));
    }
    return p;
}

TEST(CircleFit, RecoversExactCirclesAndArcs) {
    for (double span : {2 * kPi, kPi, kPi / 3}) {
        const auto p = arc({0.012, -0.034}, 100.0, 0.3, 0.3 + span, 50);
        const CircleFit f = fitCircle(p);
        EXPECT_NEAR(f.center.x(), 0.012, 1e-10);
        EXPECT_NEAR(f.center.y(), -0.034, 1e-10);
        EXPECT_NEAR(f.radius, 100.0, 1e-10);
        EXPECT_LT(f.rms, 1e-10);
    }
}

TEST(CircleFit, GeometricFitMinimisesGeometricResidualsBetterThanAlgebraic) {
    std::mt19937_64 rng(1);
    std::normal_distribution<double> noise(0, 0.5);
    auto p = arc({3, 4}, 50.0, 0, kPi / 2, 40);
    for (auto& x : p) x += Eigen::Vector2d(noise(rng), noise(rng));
    const CircleFit a = fitCircleAlgebraic(p), g = fitCircle(p);
    Eigen::VectorXd ra, rg;
    circleResiduals(p, {a.center.x(), a.center.y(), a.radius}, ra, nullptr);
    circleResiduals(p, {g.center.x(), g.center.y(), g.radius}, rg, nullptr);
    EXPECT_LE(rg.squaredNorm(), ra.squaredNorm() + 1e-12);
}

TEST(CircleFit, JacobianMatchesFiniteDifferences) {
    const auto p = arc({1, 2}, 10.0, 0, 5, 17);
    const Eigen::Vector3d x(1.3, 1.7, 9.5);
    Eigen::VectorXd r;
    Eigen::MatrixXd J;
    circleResiduals(p, x, r, &J);
    for (int k = 0; k < 3; ++k) {
        Eigen::Vector3d xp = x, xm = x;
        const double h = 1e-6;
        xp[k] += h;
        xm[k] -= h;
        Eigen::VectorXd rp, rm;
        circleResiduals(p, xp, rp, nullptr);
        circleResiduals(p, xm, rm, nullptr);
        EXPECT_LT((J.col(k) - (rp - rm) / (2 * h)).norm(), 1e-7) << k;
    }
}

TEST(CircleFit, DegenerateInputIsAnError) {
    EXPECT_THROW(fitCircle({{0, 0}, {1, 1}}), ModelError);
    EXPECT_THROW(fitCircle({{0, 0}, {1, 1}, {2, 2}, {3, 3}}), ModelError);
}

}  // namespace
}  // namespace cnccomp
