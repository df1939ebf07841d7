#pragma once
// What a LinuxCNC 2.9 configuration can take of a deviation set, and where it goes:
// - joint compensation tables (COMP_FILE_TYPE 1) take, per joint, a trim that depends on that joint's own position:
//   the positioning component error of the axis (EXX of X, ECC of C, …), a constant trim for a zero-position error
//   of a rotary axis (e.g. EB0B), and constant trims on the linear joints for offsets that sit before any rotary
//   axis in their chain (e.g. the X/Y position of a C work spindle on the bed, EX0C EY0C: the tool must follow the
//   real spindle line; on a table-table machine every tool-side offset);
// - on a table-table machine the xyzac-trt-kins / xyzbc-trt-kins HAL pins take the position of the tilt and
//   rotary axis lines (x/y/z-rot-point, y-offset or x-offset, z-offset), as absolute values in LinuxCNC's frame
//   (src/emc/kinematics/trtfuncs.c; configs/sim/axis/vismach/5axis/table-rotary-tilting/xyzac-trt.txt: "X, Y and Z
//   rot-point pins represent the offsets of the center of rotation of the C axis relative to the machine absolute
//   zero"; y/z-offset = centre of the A axis relative to the centre of the C axis). LinuxCNC's frame: joint
//   positions are the machine coordinates of the tool control point (tool length 0) from machine zero, so a point P
//   of the bed frame has LinuxCNC coordinates P − T0, T0 = the nominal tool control point at joint position 0
//   (the tool chain's fixed offsets and the axes' machine-zero included). The world frame of the module coincides
//   with the joint frame at tilt = C = 0; the work offset (G54) of the workpiece origin is its position there.
// Everything else (squareness, tilts of rotary axes, offsets behind a rotary axis with no kinematics pin,
// cross-axis component errors) is listed as not compensated, with the reason; so are the deviations the trt pins and
// the G54 take, which act in tool-tip mode only (note "tool-tip mode only: …"): the test programs run in joint mode.
#include <optional>
#include <string>
#include <vector>

#include "cnccomp/deviations.hpp"
#include "controllers/backend.hpp"
#include "controllers/linuxcnc/trt_kins.hpp"

namespace cnccomp::controllers::linuxcnc {

/// A component error a joint table takes: deviation index and the sign of its component along the axis.
struct OwnComponent {
    int deviation = -1;
    double sign = 1.0;
};

struct JointPlan {
    int axis = -1;              ///< machine axis index
    std::string name;           ///< axis letter
    bool rotary = false, modulo = false;
    double machineZero = 0.0;   ///< command (mm or rad) at which the joint reads 0 in LinuxCNC
    double constantTrim = 0.0;  ///< mm or rad
    std::vector<OwnComponent> components;
    bool hasTable() const { return constantTrim != 0.0 || !components.empty(); }
};

struct LinuxcncPlan {
    std::string coordinates;                ///< joint letters in joint order, e.g. "XYZAC"
    std::vector<JointPlan> joints;          ///< in joint order
    std::optional<TrtType> trt;             ///< table-table kinematics module, if the machine is one
    TrtPins nominalPins, pins;              ///< mm, LinuxCNC's frame (absolute)
    Vec3 nominalWorkOffset = Vec3::Zero();  ///< G54 of the description's workpiece origin, LinuxCNC's frame, mm
    Vec3 workOffset = Vec3::Zero();         ///< the same with the identified errors
    std::vector<Coverage> compensated, notCompensated;
};

/// How the NOT-compensated note of a deviation the trt pins or the G54 take begins: they act in tool-tip mode only.
inline constexpr const char* kToolTipModeOnly = "tool-tip mode only:";

/// Joint order of a LinuxCNC configuration: axis letters in XYZABCUVW order, other names after (machine order).
std::vector<int> linuxcncJointOrder(const MachineModel& m);
/// The table-table kinematics module matching the machine, if any (checks chain shape and directions).
std::optional<TrtType> matchTrt(const MachineModel& m);
/// HAL pin values of the module (absolute, LinuxCNC's frame, tool-offset 0) for the machine with a deviation set
/// (nullptr = nominal). Throws ModelError when a rotary axis of the module has a non-zero machine-zero.
TrtPins trtPins(const MachineModel& m, TrtType type, const DeviationSet* d);
/// G54 of the description's workpiece origin (the frame after the last workpiece link) in LinuxCNC's frame, mm.
Vec3 trtWorkOffset(const MachineModel& m, const DeviationSet* d);

LinuxcncPlan planLinuxcnc(const MachineModel& m, const DeviationSet& d);

/// The joint trim at a commanded position (internal units, description frame): the q' with
/// q' + Σ sign·e(q') = p + constantTrim, minus p.
double jointTrim(const MachineModel& m, const DeviationSet& d, const JointPlan& j, double position);

/// Where a joint table has its points (description frame, internal units): over the axis' whole travel (LinuxCNC
/// looks the table up at the raw joint position, without modulo, also with WRAPPED_ROTARY = 1; control.c
/// compute_screw_comp), at the breakpoints of table-type component errors (repeated every turn on a modulo axis)
/// when they fit in 256 lines, otherwise equidistant (on a modulo axis at a spacing that divides 360°, so that
/// every turn has the same points). Throws ModelError when the travel is not finite.
std::vector<double> tableNodes(const MachineModel& m, const JointPlan& j);

}  // namespace cnccomp::controllers::linuxcnc
