// Forward kinematics against [MultiTasking] eq. (1)–(13) written out independently with the paper's
// small-angle HTMs: agreement to second order in the deviations.
#include <gtest/gtest.h>

#include <random>

#include "cnccomp/error.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/kinematics.hpp"
#include "test_support.hpp"

namespace cnccomp {
namespace {

using Mat4 = Eigen::Matrix4d;

Mat4 smallHtm(double a, double b, double g, double dx, double dy, double dz) {
    Mat4 m;
    m << 1, -g, b, dx, g, 1, -a, dy, -b, a, 1, dz, 0, 0, 0, 1;
    return m;
}
Mat4 translate(double x, double y, double z) { return smallHtm(0, 0, 0, x, y, z); }

struct Paper {
    double dxBT, dzBT, aBT, aXB, bXB, gXB, gXY, aYZ, bYZ, dxCZ, dyCZ, aCZ, bCZ;
};

// Eq. (7): T = E_Z M_YZ E_Y M_XY E_X M_XB E_B M_BT T_T.
Eigen::Vector4d paperT(const Paper& p, double X, double Y, double Z, double B, double RB) {
    Mat4 EB = Mat4::Identity();
    EB(0, 0) = std::cos(B); EB(0, 2) = std::sin(B); EB(2, 0) = -std::sin(B); EB(2, 2) = std::cos(B);
    return translate(0, 0, Z) * smallHtm(p.aYZ, p.bYZ, 0, 0, 0, 0) * translate(0, Y, 0) * smallHtm(0, 0, p.gXY, 0, 0, 0) *
           translate(X, 0, 0) * smallHtm(p.aXB, p.bXB, p.gXB, 0, 0, 0) * EB * smallHtm(p.aBT, 0, 0, p.dxBT, 0, p.dzBT) *
           Eigen::Vector4d(0, 0, -RB, 1);
}

TEST(Kinematics, NominalToolBallIsCommandMinusToolVector) {
    const auto& m = test::multitasking();
    const Kinematics k(m);
    AxisVector q = AxisVector::Zero(m.axisCount());
    q[m.requireAxis("X")] = 12.5;
    q[m.requireAxis("Y")] = -3.0;
    q[m.requireAxis("Z")] = 400.0;
    q[m.requireAxis("B")] = 30.0 * kDeg;
    q[m.requireAxis("C")] = 0.0;
    const Vec3 t = k.baseToTool(q) * k.toolPoint(200.0);
    EXPECT_NEAR(t.x(), 12.5 - 200.0 * std::sin(30 * kDeg), 1e-12);
    EXPECT_NEAR(t.y(), -3.0, 1e-12);
    EXPECT_NEAR(t.z(), 400.0 - 200.0 * std::cos(30 * kDeg), 1e-12);
}

TEST(Kinematics, MatchesPaperModelToSecondOrder) {
    const auto& m = test::multitasking();
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> len(-20e-3, 20e-3), ang(-0.005 * kDeg, 0.005 * kDeg);
    for (int trial = 0; trial < 20; ++trial) {
        Paper p{len(rng), len(rng), ang(rng), ang(rng), ang(rng), ang(rng), ang(rng), ang(rng), ang(rng),
                len(rng), len(rng), ang(rng), ang(rng)};
        DeviationSet d(m);
        d.set("dxBT", p.dxBT); d.set("dzBT", p.dzBT); d.set("aBT", p.aBT); d.set("aXB", p.aXB);
        d.set("bXB", p.bXB); d.set("gXB", p.gXB); d.set("gXY", p.gXY); d.set("aYZ", p.aYZ);
        d.set("bYZ", p.bYZ); d.set("dxCZ", p.dxCZ); d.set("dyCZ", p.dyCZ); d.set("aCZ", p.aCZ); d.set("bCZ", p.bCZ);
        const Kinematics k(m, d);
        AxisVector q = AxisVector::Zero(m.axisCount());
        const double X = 150 * std::sin(trial), Y = 40.0 * std::cos(trial), Z = 500 + 30 * trial, B = 0.3 * trial - 2;
        q[m.requireAxis("X")] = X; q[m.requireAxis("Y")] = Y; q[m.requireAxis("Z")] = Z; q[m.requireAxis("B")] = B;
        const Vec3 ours = k.baseToTool(q) * k.toolPoint(360.0);
        const Eigen::Vector4d theirs = paperT(p, X, Y, Z, B, 360.0);
        // Second-order terms: (0.005°)² · 1000 mm ≈ 8e-6 mm.
        EXPECT_NEAR((ours - theirs.head<3>()).norm(), 0.0, 2e-5) << "trial " << trial;

        // Eq. (10): W = M_CZ E_C W_C for a point fixed on the C table.
        const double C = 0.7 * trial;
        q[m.requireAxis("C")] = C;
        const Vec3 wc(50, 20, 300);
        Mat4 EC = Mat4::Identity();
        EC(0, 0) = std::cos(C); EC(0, 1) = -std::sin(C); EC(1, 0) = std::sin(C); EC(1, 1) = std::cos(C);
        const Eigen::Vector4d W = smallHtm(p.aCZ, p.bCZ, 0, p.dxCZ, p.dyCZ, 0) * EC * Eigen::Vector4d(wc.x(), wc.y(), wc.z(), 1);
        EXPECT_NEAR((k.baseToWorkpiece(q) * wc - W.head<3>()).norm(), 0.0, 2e-5);
    }
}

TEST(Kinematics, RotationsAreExactNotSmallAngle) {
    // A 1° location error must give an exactly orthonormal pose; the small-angle HTM would not.
    const auto& m = test::multitasking();
    DeviationSet d(m);
    d.set("aXB", 1.0 * kDeg);
    const Kinematics k(m, d);
    AxisVector q = AxisVector::Zero(m.axisCount());
    q[m.requireAxis("B")] = 0.5;
    const Mat3 r = k.baseToTool(q).linear();
    EXPECT_NEAR((r * r.transpose() - Mat3::Identity()).norm(), 0.0, 1e-14);
}

TEST(Kinematics, TravelLimitsAreChecked) {
    const auto& m = test::multitasking();
    const Kinematics k(m);
    AxisVector q = AxisVector::Zero(m.axisCount());
    q[m.requireAxis("X")] = 5000;
    EXPECT_THROW(k.checkTravel(q), ModelError);
    q[m.requireAxis("X")] = std::nan("");
    EXPECT_THROW(k.checkTravel(q), ModelError);
}

}  // namespace
}  // namespace cnccomp
