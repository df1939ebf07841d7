#pragma once
// The LinuxCNC table-rotary-tilting kinematics modules xyzac-trt-kins and xyzbc-trt-kins
// (src/emc/kinematics/trtfuncs.c of LinuxCNC 2.9: tags v2.9.0 … v2.9.10 and Debian 12's 2.9.0~pre1 carry the same
// formulas): their HAL pins and their forward/inverse transformations, written out from the module's formulas so
// that the apply model reproduces what LinuxCNC computes (tests/linuxcnc compares it with the real LinuxCNC).
// Not LinuxCNC 2.10/master: there trtfuncs.c has a pin conventional-directions (default 0 = the 2.9 directions), and
// its xyzbc inverse computes dpx = −cos(B)·dx + sin(B)·dz + dx, dpz = −sin(B)·dx − cos(B)·dz + dz (2.9: −sin(B)·dz and
// +sin(B)·dx), which with conventional-directions = 0 is not the inverse of its own forward; xyzac is unchanged.
// Positions in mm, angles in degrees (LinuxCNC units).
#include <array>
#include <string>

namespace cnccomp::controllers::linuxcnc {

enum class TrtType { AC, BC };

struct TrtPins {
    double xRotPoint = 0, yRotPoint = 0, zRotPoint = 0;
    double xOffset = 0, yOffset = 0, zOffset = 0;  ///< AC uses y, z; BC uses x, z
    double toolOffset = 0;
};

/// Cartesian tool position (x y z) and the two rotary angles (tilt: A or B, then C), degrees.
struct TrtPose {
    std::array<double, 3> xyz{};
    double tilt = 0, c = 0;
};

/// Module name, "xyzac-trt-kins" / "xyzbc-trt-kins".
std::string trtModule(TrtType t);
/// Joint positions (x y z tilt c) → world pose.
TrtPose trtForward(TrtType t, const TrtPins& p, const TrtPose& joints);
/// World pose → joint positions.
TrtPose trtInverse(TrtType t, const TrtPins& p, const TrtPose& world);

}  // namespace cnccomp::controllers::linuxcnc
