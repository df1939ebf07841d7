#include "controllers/linuxcnc/trt_kins.hpp"

#include <cmath>

namespace cnccomp::controllers::linuxcnc {
namespace {
constexpr double kToRad = 3.14159265358979323846 / 180.0;
}

std::string trtModule(TrtType t) { return t == TrtType::AC ? "xyzac-trt-kins" : "xyzbc-trt-kins"; }

// The formulas of trtfuncs.c, xyzacKinematicsForward/Inverse and xyzbcKinematicsForward/Inverse.
TrtPose trtForward(TrtType t, const TrtPins& p, const TrtPose& j) {
    TrtPose w;
    w.tilt = j.tilt;
    w.c = j.c;
    const double xr = p.xRotPoint, yr = p.yRotPoint, zr = p.zRotPoint;
    const double sc = std::sin(j.c * kToRad), cc = std::cos(j.c * kToRad);
    const double st = std::sin(j.tilt * kToRad), ct = std::cos(j.tilt * kToRad);
    const double X = j.xyz[0], Y = j.xyz[1], Z = j.xyz[2];
    if (t == TrtType::AC) {
        const double dy = p.yOffset, dz = p.zOffset + p.toolOffset;
        w.xyz[0] = cc * (X - xr) + sc * ct * (Y - dy - yr) + sc * st * (Z - dz - zr) + sc * dy + xr;
        w.xyz[1] = -sc * (X - xr) + cc * ct * (Y - dy - yr) + cc * st * (Z - dz - zr) + cc * dy + yr;
        w.xyz[2] = -st * (Y - dy - yr) + ct * (Z - dz - zr) + dz + zr;
    } else {
        const double dx = p.xOffset, dz = p.zOffset + p.toolOffset;
        w.xyz[0] = cc * ct * (X - dx - xr) + sc * (Y - yr) - cc * st * (Z - dz - zr) + cc * dx + xr;
        w.xyz[1] = -sc * ct * (X - dx - xr) + cc * (Y - yr) + sc * st * (Z - dz - zr) - sc * dx + yr;
        w.xyz[2] = st * (X - dx - xr) + ct * (Z - dz - zr) + dz + zr;
    }
    return w;
}

TrtPose trtInverse(TrtType t, const TrtPins& p, const TrtPose& w) {
    TrtPose j;
    j.tilt = w.tilt;
    j.c = w.c;
    const double xr = p.xRotPoint, yr = p.yRotPoint, zr = p.zRotPoint;
    const double sc = std::sin(w.c * kToRad), cc = std::cos(w.c * kToRad);
    const double st = std::sin(w.tilt * kToRad), ct = std::cos(w.tilt * kToRad);
    const double x = w.xyz[0] - xr, y = w.xyz[1] - yr, z = w.xyz[2] - zr;
    if (t == TrtType::AC) {
        const double dy = p.yOffset, dz = p.zOffset + p.toolOffset;
        j.xyz[0] = cc * x - sc * y + xr;
        j.xyz[1] = sc * ct * x + cc * ct * y - st * z - ct * dy + st * dz + dy + yr;
        j.xyz[2] = sc * st * x + cc * st * y + ct * z - st * dy - ct * dz + dz + zr;
    } else {
        const double dx = p.xOffset, dz = p.zOffset + p.toolOffset;
        const double dpx = -ct * dx - st * dz + dx;
        const double dpz = st * dx - ct * dz + dz;
        j.xyz[0] = cc * ct * x - sc * ct * y + st * z + dpx + xr;
        j.xyz[1] = sc * x + cc * y + yr;
        j.xyz[2] = -cc * st * x + sc * st * y + ct * z + dpz + zr;
    }
    return j;
}

}  // namespace cnccomp::controllers::linuxcnc
