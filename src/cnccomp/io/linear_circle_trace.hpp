#pragma once
// Instrument files of the circles of the linear axes (<circle> runs, linear_circle_run.hpp): read with the ball-bar
// import (io/trace_import.hpp: angle- or time-sampled, CCW / CW passes, columns, units, decimal comma, drift, feed
// check, feed-in / feed-out arcs dropped, gaps and coverage of the data arc checked), and written the same way by
// `simulate`. The circle's own `# key: value` lines are checked against the run: plane, radius (also as LB), start,
// arc, end, step, feed; `# date:`, `# instrument:` and `# operator:` are kept as test conditions.
#include <string>
#include <vector>

#include "cnccomp/io/trace_import.hpp"
#include "cnccomp/linear_circle_run.hpp"

namespace cnccomp::io {

struct LinearCircleTrace {
    MeasuredTrace measured;                      ///< the passes, angles in θ of the circle (deg)
    std::string date, instrument, operatorName;  ///< from the file's `# date:` / `# instrument:` / `# operator:` lines
};

/// The ball-bar run the import checks a circle's file against: bar length = radius, sweep = the data arc, the
/// circle's capture with the feed measured on the circle's radius.
BallbarRun linearCircleImportRun(const LinearCircleRun& run);

/// Reads DIR/<run>.csv style file `path` of `run`. InputError naming the file and line: a pass that does not cover
/// the data arc, the file of another run (plane, radius, arc …), a unit mistake, a feed that does not fit the data.
LinearCircleTrace importLinearCircleTrace(const std::string& path, const LinearCircleRun& run,
                                          const std::string& machine = "");

/// The passes (simulateLinearCircle) as the run's instrument writes them: the capture's columns and units, a pass
/// column (ccw / cw) for two passes, the circle's metadata lines; time-sampled (t from the first sample, 1 s between
/// the passes) or angle-sampled.
std::string formatLinearCircleTrace(const LinearCircleRun& run, const std::vector<DirectedTrace>& passes, bool timeSampled,
                                    const std::string& machine);

}  // namespace cnccomp::io
