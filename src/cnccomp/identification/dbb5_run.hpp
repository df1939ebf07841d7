#pragma once
// Commands and simulation of a DBB5 run (Ibaraki et al., 1st report); the run itself (geometry, sweep angles) is
// measurement/dbb5_run.hpp.
#include <utility>

#include "cnccomp/ballbar.hpp"
#include "cnccomp/measurement/dbb5_run.hpp"

namespace cnccomp::identification {

/// Axis commands at sweep angle `angleDeg` (nominal machine): spindle ball on its target.
AxisVector dbb5Commands(const MachineModel& m, const measurement::Dbb5Run& run, double angleDeg);
/// Setup commands: spindle ball on the nominal table ball (at the sweep angle setupDeg for rotary circles and cone
/// frustums).
AxisVector dbb5SetupCommands(const MachineModel& m, const measurement::Dbb5Run& run);

/// Simulates ΔL along the sweep on machine `k` (angle_deg, ΔL as for a ball-bar trace). Throws ModelError naming
/// the run when a command leaves an axis' travel.
BallbarTrace simulateDbb5(const Kinematics& k, const measurement::Dbb5Run& run);

/// Line of rotary axis `axis` (point, unit direction, bed frame) on machine `k` at commands q; ModelError when the axis
/// has no joint frame.
std::pair<Vec3, Vec3> rotaryAxisLine(const Kinematics& k, int axis, const AxisVector& q);

}  // namespace cnccomp::identification
