#pragma once
// R-test runs ([Moravek2019] section 3): a precision ball fixed on the table, a sensor nest on the spindle that
// measures the 3D displacement of the ball centre while the rotary axes move and the linear axes keep the nest
// on the ball (on the nominal machine). XYC, YZA and XYZAC trajectories are sweeps of the rotary axes.
// The run as planned (a measurement); its commands and simulation are identification/rtest_run.hpp.
#include <string>
#include <vector>

#include "cnccomp/geometry.hpp"

namespace cnccomp::measurement {

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

}  // namespace cnccomp::measurement
