#pragma once
// What a LinuxCNC configuration can take of a deviation set, and where it goes:
// - joint compensation tables (COMP_FILE_TYPE 1) take, per joint, a trim that depends on that joint's own position:
//   the positioning component error of the axis (EXX of X, ECC of C, …), a constant trim for a zero-position error
//   of a rotary axis (e.g. EB0B), and constant trims on the linear joints for offsets that sit before any rotary
//   axis in their chain (e.g. the X/Y position of a C work spindle on the bed, EX0C EY0C: the tool must follow the
//   real spindle line);
// - on a table-table machine the xyzac-trt-kins / xyzbc-trt-kins HAL pins take the position of the tilt and
//   rotary axis lines (x/y/z-rot-point, y-offset or x-offset, z-offset), as in trtfuncs.c.
// Everything else (squareness, tilts of rotary axes, offsets behind a rotary axis with no kinematics pin,
// cross-axis component errors) is listed as not compensated, with the reason.
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
    double constantTrim = 0.0;  ///< mm or rad
    std::vector<OwnComponent> components;
    bool hasTable() const { return constantTrim != 0.0 || !components.empty(); }
};

struct LinuxcncPlan {
    std::string coordinates;                ///< joint letters in joint order, e.g. "XYZAC"
    std::vector<JointPlan> joints;          ///< in joint order
    std::optional<TrtType> trt;             ///< table-table kinematics module, if the machine is one
    TrtPins nominalPins, pins;              ///< mm
    std::array<double, 3> workOffsetShift{};  ///< corrected − nominal rotation point, mm (work offsets move by it)
    std::vector<Coverage> compensated, notCompensated;
};

/// Joint order of a LinuxCNC configuration: axis letters in XYZABCUVW order, other names after (machine order).
std::vector<int> linuxcncJointOrder(const MachineModel& m);
/// The table-table kinematics module matching the machine, if any (checks chain shape and directions).
std::optional<TrtType> matchTrt(const MachineModel& m);
/// HAL pin values of the module for the machine with a deviation set (nullptr = nominal).
TrtPins trtPins(const MachineModel& m, TrtType type, const DeviationSet* d);

LinuxcncPlan planLinuxcnc(const MachineModel& m, const DeviationSet& d);

/// The joint trim at a commanded position (internal units): the q' with q' + Σ sign·e(q') = p + constantTrim,
/// minus p.
double jointTrim(const MachineModel& m, const DeviationSet& d, const JointPlan& j, double position);

}  // namespace cnccomp::controllers::linuxcnc
