#pragma once
// R-test runs (seed 001 section 3): a precision ball fixed on the table, a sensor nest on the spindle that
// measures the 3D displacement of the ball centre while the rotary axes move and the linear axes keep the nest
// on the ball (on the nominal machine). XYC, YZA and XYZAC trajectories are sweeps of the rotary axes.
#include <string>
#include <vector>

#include "cnccomp/kinematics.hpp"

namespace cnccomp {

/// One rotary axis during a run: linear in the sample index from start to end (degrees); start == end holds it.
struct RotarySweep {
    std::string axis;
    double startDeg = 0.0, endDeg = 0.0;
};

struct RtestRun {
    std::string name;
    Vec3 ball = Vec3::Zero();         ///< nominal ball centre in the workpiece (table) frame, mm
    double nestLength = 100.0;        ///< nest centre: distance along the tool direction from the last tool frame, mm
    std::vector<RotarySweep> sweeps;  ///< rotary axes not listed stay at 0
    int steps = 36;                   ///< intervals; a sweep of whole turns does not repeat its first pose
    Vec3 ballOffset = Vec3::Zero();   ///< actual minus nominal ball centre (mounting error, simulation), mm
    bool estimateBall = false;        ///< identification: the ball offset is a nuisance parameter (3 values)

    /// Throws ModelError for non-finite geometry, steps outside 1 .. 10⁶, an axis given twice or no moving axis.
    void validate() const;
    /// Number of poses.
    int sampleCount() const;
    /// Angle (deg) of sweep `s` at pose i.
    double angleDeg(int s, int i) const;
};

/// Axis values at which the tool point `toolPoint` (tool frame) of machine `k` sits on `target` (workpiece frame):
/// the linear axes are solved by Newton's method, the other axes keep their values from `q`.
/// Throws ModelError when the linear axes cannot reach the point (fewer than three, or singular).
AxisVector followPoint(const Kinematics& k, AxisVector q, const Vec3& toolPoint, const Vec3& target);

/// Axis commands of every pose: the rotary axes on their sweeps, the linear axes from followPoint on the
/// nominal machine so that the nest centre sits on the nominal ball centre. Throws ModelError (naming the run)
/// for an unknown or non-rotary axis and for commands outside the travel.
std::vector<AxisVector> rtestCommands(const MachineModel& m, const RtestRun& run);

/// Displacement of the ball centre from the nest centre in the tool (sensor) frame: d = tMw·ball − nest.
/// Zero on the nominal machine at the commands of rtestCommands().
Vec3 rtestDisplacement(const Kinematics& k, const AxisVector& q, const Vec3& ballInWorkpiece, const Vec3& nestInTool);

struct RtestTrace {
    std::vector<AxisVector> commands;
    std::vector<Vec3> d;  ///< displacement of every pose, mm
};

/// Simulates a run on machine `k`, the ball at ball + ballOffset.
RtestTrace simulateRtest(const Kinematics& k, const RtestRun& run);
/// Same, for precomputed commands (rtestCommands).
RtestTrace simulateRtest(const Kinematics& k, const RtestRun& run, const std::vector<AxisVector>& commands);

}  // namespace cnccomp
