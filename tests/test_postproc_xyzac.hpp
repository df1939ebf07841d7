#pragma once
// The machine of LinuxCNC's switchable xyzac-trt sim (configs/sim/axis/vismach/5axis/table-rotary-tilting/xyzac-trt.ini:
// y-offset 20, z-offset 10, rot-points 0, conventional-directions 0), with the location errors the TCP tests and the
// benchmark use: A tilts the table about X through y = 20, z = 10; C turns on it through the machine origin.
#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "cnccomp/geometry.hpp"

namespace cnccomp::test {

inline constexpr const char* kXyzacTrtMachine = R"xml(<?xml version="1.0" encoding="UTF-8"?>
<machine name="linuxcnc-xyzac-trt" description="LinuxCNC sim xyzac-trt-kins: A tilts the table about X through y=20 z=10, C turns on it through the machine origin">
  <workpiece>
    <axis name="A" type="rotary" direction="1 0 0" min="-100" max="50" offset="0 20 10"/>
    <axis name="C" type="rotary" direction="0 0 1" min="-36000" max="36000" offset="0 -20 -10"/>
  </workpiece>
  <tool direction="0 0 -1">
    <axis name="X" type="linear" direction="1 0 0" min="-200" max="200"/>
    <axis name="Y" type="linear" direction="0 1 0" min="-100" max="100"/>
    <axis name="Z" type="linear" direction="0 0 1" min="-120" max="120"/>
  </tool>
  <deviations>
    <location name="EY0A" link="A" component="y"/>
    <location name="EZ0A" link="A" component="z"/>
    <location name="EA0A" link="A" component="a"/>
    <location name="EB0A" link="A" component="b"/>
    <location name="EC0A" link="A" component="c"/>
    <location name="EX0C" link="C" component="x"/>
    <location name="EY0C" link="C" component="y"/>
    <location name="EA0C" link="C" component="a"/>
    <location name="EB0C" link="C" component="b"/>
    <location name="EC0Y" link="Y" component="c"/>
  </deviations>
</machine>
)xml";


// --- Independent models of this machine for the tests (written from LinuxCNC's source and README's definition, not
// from the corrector): the controller's TCP kinematics and the erroneous machine.
namespace xyzac {

inline constexpr double kYOffset = 20.0, kZOffset = 10.0;  // xyzac-trt.ini: sets :y-offset 20, sets :z-offset 10

// The deviations (µm, arcsec) as the independent model uses them, and as CSV for the corrector.
struct Errors {
    double ay = 8, az = -12, aa = 12, ab = 10, ac = -6;  // A: EY0A EZ0A EA0A EB0A EC0A
    double cx = 15, cy = -9, ca = 7, cb = -5;            // C: EX0C EY0C EA0C EB0C
    double yc = 4;                                       // Y: EC0Y
};
inline const char* kDeviationCsv =
    "# cnccomp-deviations/2\nname,alias,value,unit\nEY0A,,8,um\nEZ0A,,-12,um\nEA0A,,12,arcsec\nEB0A,,10,arcsec\nEC0A,,-6,arcsec\n"
    "EX0C,,15,um\nEY0C,,-9,um\nEA0C,,7,arcsec\nEB0C,,-5,arcsec\nEC0Y,,4,arcsec\n";

struct World {
    double x = 0, y = 0, z = 0, a = 0, c = 0;  // mm, deg
};
struct Joints {
    double x = 0, y = 0, z = 0, a = 0, c = 0;
};

// --- LinuxCNC trtfuncs.c, xyzac, transcribed (x/y/z-rot-point 0; dz = z-offset + tool-offset) ------------------------
inline constexpr double kCon = -1.0;  // conventional-directions false

inline Joints trtInverse(const World& p, double toolOffset) {
    const double dy = kYOffset, dz = kZOffset + toolOffset, a = p.a * kDeg, c = p.c * kDeg;
    Joints j;
    j.x = std::cos(c) * p.x + kCon * std::sin(c) * p.y;
    j.y = -kCon * std::sin(c) * std::cos(a) * p.x + std::cos(c) * std::cos(a) * p.y + kCon * std::sin(a) * p.z -
          std::cos(a) * dy - kCon * std::sin(a) * dz + dy;
    j.z = std::sin(c) * std::sin(a) * p.x - kCon * std::cos(c) * std::sin(a) * p.y + std::cos(a) * p.z +
          kCon * std::sin(a) * dy - std::cos(a) * dz + dz;
    j.a = p.a;
    j.c = p.c;
    return j;
}

inline World trtForward(const Joints& j, double toolOffset) {
    const double dy = kYOffset, dz = kZOffset + toolOffset, a = j.a * kDeg, c = j.c * kDeg;
    World p;
    p.x = std::cos(c) * j.x - kCon * std::sin(c) * std::cos(a) * (j.y - dy) + std::sin(c) * std::sin(a) * (j.z - dz) -
          kCon * std::sin(c) * dy;
    p.y = kCon * std::sin(c) * j.x + std::cos(c) * std::cos(a) * (j.y - dy) - kCon * std::cos(c) * std::sin(a) * (j.z - dz) +
          std::cos(c) * dy;
    p.z = kCon * std::sin(a) * (j.y - dy) + std::cos(a) * (j.z - dz) + dz;
    p.a = j.a;
    p.c = j.c;
    return p;
}

// --- The machine, composed by hand --------------------------------------------------------------------------------
struct Rigid {
    Mat3 R = Mat3::Identity();
    Vec3 t = Vec3::Zero();
    Rigid operator*(const Rigid& o) const { return {R * o.R, R * o.t + t}; }
    Vec3 operator*(const Vec3& p) const { return R * p + t; }
    Rigid inverse() const { return {R.transpose(), -(R.transpose() * t)}; }
};
inline Rigid shift(double x, double y, double z) { return {Mat3::Identity(), Vec3(x, y, z)}; }
inline Rigid turn(const Vec3& axis, double rad) { return {Eigen::AngleAxisd(rad, axis).toRotationMatrix(), Vec3::Zero()}; }
/// Location error: translation (µm) then rotation by the rotation vector (arcsec).
inline Rigid error(double x, double y, double z, double a, double b, double c) {
    const Vec3 w = Vec3(a, b, c) * kArcsec;
    Rigid e;
    if (w.norm() > 0) e.R = Eigen::AngleAxisd(w.norm(), w / w.norm()).toRotationMatrix();
    e.t = Vec3(x, y, z) * kUm;
    return e;
}

struct ToolTip {
    Vec3 tip, axis;  // table frame
};

/// Tool tip (length L below the tool frame origin) and tool axis in the table (C) frame.
inline ToolTip machineTip(const Joints& j, double L, const Errors* e) {
    const Errors zero{0, 0, 0, 0, 0, 0, 0, 0, 0, 0};
    const Errors& d = e ? *e : zero;
    const Rigid bMw = shift(0, kYOffset, kZOffset) * error(0, d.ay, d.az, d.aa, d.ab, d.ac) * turn(Vec3::UnitX(), j.a * kDeg) *
                      shift(0, -kYOffset, -kZOffset) * error(d.cx, d.cy, 0, d.ca, d.cb, 0) * turn(Vec3::UnitZ(), j.c * kDeg);
    const Rigid bMt = shift(j.x, 0, 0) * error(0, 0, 0, 0, 0, d.yc) * shift(0, j.y, 0) * shift(0, 0, j.z);
    const Rigid wMb = bMw.inverse();
    return {wMb * (bMt * Vec3(0, 0, -L)), wMb.R * (bMt.R * Vec3(0, 0, -1))};
}

/// Distance from p to a path given by its point at each parameter t ∈ [0, 1]: dense samples, then a ternary
/// refinement around the closest; the parameter of the closest point in `at`.
template <class PointAt>
double distanceToPath(const PointAt& pointAt, const Vec3& p, double* at = nullptr) {
    const int n = 48;
    double best = HUGE_VAL, bestT = 0;
    auto dist = [&](double t) { return (pointAt(t) - p).norm(); };
    for (int k = 0; k <= n; ++k) {
        const double t = double(k) / n, d = dist(t);
        if (d < best) best = d, bestT = t;
    }
    double lo = std::max(0.0, bestT - 1.0 / n), hi = std::min(1.0, bestT + 1.0 / n);
    for (int it = 0; it < 50; ++it) {
        const double m1 = lo + (hi - lo) / 3, m2 = hi - (hi - lo) / 3;
        const double d1 = dist(m1), d2 = dist(m2);
        if (d1 < d2) hi = m2;
        else lo = m1;
        if (d1 < best) best = d1, bestT = m1;
        if (d2 < best) best = d2, bestT = m2;
    }
    if (at) *at = bestT;
    return best;
}

}  // namespace xyzac

}  // namespace cnccomp::test
