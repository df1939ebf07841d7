// Fits of [Moravek2019] section 2.2 (Gander, Golub & Strebel 1994): planes, circles in 3D, ellipses (algebraic,
// geometric, parametric with known phases) against exactly constructed shapes, and eq. (2) on a sheared circle.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "cnccomp/error.hpp"
#include "cnccomp/identification/rtest_fit.hpp"

namespace cnccomp {
using namespace cnccomp::identification;
namespace {

using Vec2 = Eigen::Vector2d;

std::vector<Vec2> ellipsePoints(const Vec2& c, double a, double b, double angle, int n, double phase0 = 0.3,
                                std::vector<double>* phases = nullptr) {
    std::vector<Vec2> p;
    for (int i = 0; i < n; ++i) {
        const double t = phase0 + 2 * kPi * i / n;
        if (phases) phases->push_back(t);
        const Vec2 local(a * std::cos(t), b * std::sin(t));
        p.push_back(c + Eigen::Rotation2Dd(angle) * local);
    }
    return p;
}

TEST(RtestFit, PlaneAndCircleIn3d) {
    // A circle of radius 80 about a tilted axis through (5, -3, 40).
    const Vec3 n = Vec3(0.01, -0.02, 1).normalized();
    const Vec3 u = n.cross(Vec3::UnitX()).normalized(), v = n.cross(u);
    std::vector<Vec3> pts;
    for (int i = 0; i < 40; ++i) {
        const double t = 0.1 + i * 0.04;  // an arc of 90 deg
        pts.push_back(Vec3(5, -3, 40) + 80 * (std::cos(t) * u + std::sin(t) * v));
    }
    const Circle3Fit c = fitCircle3(pts, Vec3::UnitZ());
    EXPECT_LT((c.center - Vec3(5, -3, 40)).norm(), 1e-9);
    EXPECT_LT((c.normal - n).norm(), 1e-12);
    EXPECT_NEAR(c.radius, 80, 1e-9);
    EXPECT_LT(c.rms, 1e-9);
    const PlaneFit p = fitPlane(pts, -Vec3::UnitZ());
    EXPECT_LT((p.normal + n).norm(), 1e-12);  // oriented along the hint
    EXPECT_THROW(fitPlane({Vec3(0, 0, 0), Vec3(1, 1, 1), Vec3(2, 2, 2), Vec3(3, 3, 3)}, Vec3::UnitZ()), ModelError);
}

TEST(RtestFit, EllipseFitsRecoverAnExactEllipse) {
    std::vector<double> phases;
    const auto pts = ellipsePoints(Vec2(12, -7), 60, 35, 0.4, 36, 0.3, &phases);
    for (const EllipseFit& e : {fitEllipseAlgebraic(pts), fitEllipse(pts), fitEllipsePhases(pts, phases)}) {
        EXPECT_LT((e.center - Vec2(12, -7)).norm(), 1e-9);
        EXPECT_NEAR(e.a, 60, 1e-9);
        EXPECT_NEAR(e.b, 35, 1e-9);
        EXPECT_NEAR(e.angle, 0.4, 1e-10);
    }
    // Axes given the other way round, angle outside (−90°, 90°]: normalised to a ≥ b.
    const EllipseFit f = fitEllipse(ellipsePoints(Vec2(0, 0), 20, 50, 2.0, 30));
    EXPECT_NEAR(f.a, 50, 1e-9);
    EXPECT_NEAR(f.b, 20, 1e-9);
    EXPECT_NEAR(f.angle, 2.0 + kPi / 2 - kPi, 1e-10);
    EXPECT_THROW(fitEllipseAlgebraic({Vec2(0, 0), Vec2(1, 0), Vec2(2, 0), Vec2(3, 0), Vec2(4, 0)}), ModelError);
}

TEST(RtestFit, GeometricFitBeatsAlgebraicOnNoisyArcs) {
    std::mt19937_64 rng(7);
    std::normal_distribution<double> g(0, 0.05);
    auto pts = ellipsePoints(Vec2(0, 0), 100, 40, 0.2, 60);
    pts.resize(30);  // half the ellipse
    for (auto& p : pts) p += Vec2(g(rng), g(rng));
    const EllipseFit alg = fitEllipseAlgebraic(pts), geo = fitEllipse(pts);
    EXPECT_LE(geo.rms, alg.rms + 1e-15);  // the geometric fit minimises exactly that
    EXPECT_NEAR(geo.a, 100, 1.0);
    EXPECT_NEAR(geo.b, 40, 1.0);
    // The residual of the geometric fit is the distance of each point to the ellipse.
    double ss = 0;
    for (const auto& p : pts) ss += std::pow(ellipseDistance(geo, p), 2);
    EXPECT_NEAR(std::sqrt(ss / pts.size()), geo.rms, 1e-9);
}

TEST(RtestFit, DiametersOfAShearedCircleGiveEquationTwo) {
    // Circle of radius R sheared by y += γx: D45 − D135 = γ·D0 to first order ([Moravek2019] eq. (1)–(2)).
    const double R = 150, gamma = 20e-6;
    std::vector<Vec2> pts;
    std::vector<double> ph;
    for (int i = 0; i < 72; ++i) {
        const double t = i * 5 * kDeg;
        pts.emplace_back(R * std::cos(t), R * std::sin(t) + gamma * R * std::cos(t));
        ph.push_back(t);
    }
    const EllipseFit e = fitEllipse(pts);
    const double c = (ellipseDiameter(e, 45 * kDeg) - ellipseDiameter(e, 135 * kDeg)) / (2 * R);
    EXPECT_NEAR(c, gamma, gamma * gamma * 2);
    // A circle seen edge-on (thin ellipse): the parametric fit gives its length as the long diameter.
    std::vector<Vec2> seg;
    for (double t : ph) seg.emplace_back(R * std::sin(t) * std::cos(0.3), R * std::sin(t) * std::sin(0.3));
    const EllipseFit s = fitEllipsePhases(seg, ph);
    EXPECT_NEAR(s.a, R, 1e-9);
    EXPECT_NEAR(s.b, 0, 1e-9);
    EXPECT_NEAR(s.angle, 0.3, 1e-12);
}

}  // namespace
}  // namespace cnccomp
