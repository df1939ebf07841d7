#pragma once
// Commands and simulation of an R-test run ([Moravek2019] section 3); the run itself is measurement/rtest_run.hpp.
#include <vector>

#include "cnccomp/kinematics.hpp"
#include "cnccomp/measurement/rtest_run.hpp"

namespace cnccomp::identification {

/// Axis values at which the tool point `toolPoint` (tool frame) of machine `k` sits on `target` (workpiece frame):
/// the linear axes are solved by Newton's method, the other axes keep their values from `q`.
/// Throws ModelError when the linear axes cannot reach the point (fewer than three, or singular).
AxisVector followPoint(const Kinematics& k, AxisVector q, const Vec3& toolPoint, const Vec3& target);

/// Axis commands of every pose: the rotary axes on their sweeps, the linear axes from followPoint on the
/// nominal machine so that the nest centre sits on the nominal ball centre. Throws ModelError (naming the run)
/// for an unknown or non-rotary axis and for commands outside the travel.
std::vector<AxisVector> rtestCommands(const MachineModel& m, const measurement::RtestRun& run);

/// Displacement of the ball centre from the nest centre in the tool (sensor) frame: d = tMw·ball − nest.
/// Zero on the nominal machine at the commands of rtestCommands().
Vec3 rtestDisplacement(const Kinematics& k, const AxisVector& q, const Vec3& ballInWorkpiece, const Vec3& nestInTool);

struct RtestTrace {
    std::vector<AxisVector> commands;
    std::vector<Vec3> d;  ///< displacement of every pose, mm
};

/// Simulates a run on machine `k`, the ball at ball + ballOffset.
RtestTrace simulateRtest(const Kinematics& k, const measurement::RtestRun& run);
/// Same, for precomputed commands (rtestCommands).
RtestTrace simulateRtest(const Kinematics& k, const measurement::RtestRun& run, const std::vector<AxisVector>& commands);

}  // namespace cnccomp::identification
