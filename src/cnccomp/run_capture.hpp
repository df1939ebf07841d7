#pragma once
// How a measured ball-bar run was recorded and exported, from the plan: the run's programme (feed, directions,
// overshoot) and the instrument's file layout (columns, units, relative length, drift). The trace import
// (io/trace_import.hpp) reads a file with it and checks the file against the run. The defaults describe cnccomp's
// own traces: `angle_deg,dL_um`, one pass in the direction of the plan's step, absolute length, no drift removal.
#include <string>
#include <vector>

namespace cnccomp {

struct RunCapture {
    // --- the run's programme (<run> attributes feed, feed-radius, overshoot, directions) ---
    double feed = 0;          ///< contouring feed F, mm/min; needed for time-sampled files (0 = not given)
    double feedRadius = 0;    ///< radius of the path F is measured on, mm; 0 = radius of the linear axes' circle
    double overshootDeg = 0;  ///< feed-in arc before the sweep (and feed-out arc after it), deg
    /// Directions of the recorded passes in order: +1 = CCW (axis angle increasing, right-hand about the axis
    /// direction), −1 = CW. Empty = one pass in the direction of the plan's step (start → end).
    std::vector<int> passes;

    // --- the instrument and its export (<instrument> attributes, or the same on a <run>) ---
    std::string angleColumn = "angle_deg";  ///< angle-sampled layout
    std::string timeColumn = "t_s";         ///< time-sampled layout (used when the angle column is absent)
    std::string lengthColumn = "dL_um";     ///< measured ΔL = L − LB (eq. (14))
    std::string passColumn = "pass";        ///< optional: 1/2, ccw/cw or +/−, which pass a sample belongs to
    double lengthUnit = 1e-3;               ///< mm per unit of the length column (µm)
    double angleUnit = 1.0;                 ///< deg per unit of the angle column
    double timeUnit = 1.0;                  ///< s per unit of the time column
    char decimal = 0;                       ///< '.' or ','; 0 = either (',' only where the separator is not ',')
    bool relativeLength = false;            ///< the instrument does not know its absolute length: a per-run
                                            ///< offset is estimated with the deviations (nuisance "<run>.dL0")
    bool removeDrift = false;               ///< remove a drift linear in time (needs a closed sweep or two passes)

    bool operator==(const RunCapture&) const = default;
};

}  // namespace cnccomp
