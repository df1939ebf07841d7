#pragma once
// Import of measured ball-bar traces, checked against their run of the plan.
//
// Accepted layouts (README "Measured ball-bar data"; the names are those of RunCapture, set in the plan):
//  - angle-sampled: columns `angle_deg,dL_um` (ΔL = L − LB, eq. (14)), the angle being the run's sweep angle in the
//    plan's frame (the rotary axis position of Table 2);
//  - time-sampled: columns `t_s,dL_um`; the angle of a sample is start + d·ω·(t − t_first) of its pass, ω = feed /
//    feed-radius, the pass starting `overshoot` degrees before its end of the sweep (d = +1 CCW, −1 CW);
//  - an optional `pass` column (1/2, ccw/cw, +/−) separates a CCW and a CW pass in one file; without it the passes
//    are split where the angle turns back (angle-sampled) or where the time starts again (time-sampled);
//  - separators `,` `;` or tab (from the header line); decimal comma where the separator is not a comma; cells may be
//    quoted; a UTF-8 byte-order mark is skipped; `#` lines are comments, `# key: value` lines are the file's own run
//    metadata (run, test, machine, LB, RB, RC, ZC, start, end, step, feed) and must match the run;
//  - empty ΔL cells are missing samples (skipped and counted); any other text where a number belongs is an error.
// Samples outside the sweep (feed-in / feed-out overshoot) are dropped. Each pass must then run in its direction,
// cover the sweep without a gap wider than max(4 steps, 2°), and hold at least 3/4 of the samples the plan's step
// gives (and at least five). Violations are InputErrors naming the file and line. A pass with more than four samples a
// step is then averaged into bins of the plan's step (mean angle, mean ΔL; TraceImportSummary::binnedFrom/binnedInto).
#include <string>
#include <vector>

#include "cnccomp/ballbar.hpp"
#include "cnccomp/circular_test.hpp"

namespace cnccomp::io {

/// What the import did with a file, for messages and the report.
struct TraceImportSummary {
    std::string layout;       ///< "angle" or "time"
    int rows = 0;             ///< data rows read
    int missing = 0;          ///< rows without a ΔL value, skipped
    int trimmed = 0;          ///< samples outside the sweep (feed-in / feed-out), dropped
    int metadataChecked = 0;  ///< "# key: value" lines checked against the run
    double driftRemoved = 0;  ///< ΔL drift removed between the first and the last sample, mm (0: not asked)
    double feedEstimate = 0;  ///< time-sampled: the feed the passes' durations give, mm/min (0: not estimated)
    double feedTolerance = 0; ///< relative deviation from the plan's feed allowed for that file (refused beyond)
    int binnedFrom = 0;       ///< samples averaged into bins of the plan's step (0: the file was not denser than 4 a step)
    int binnedInto = 0;       ///< the bins they gave
};

struct MeasuredTrace {
    std::string path;
    BallbarTrace trace;                 ///< every kept sample, the passes one after the other (what identify fits)
    std::vector<DirectedTrace> passes;  ///< the same samples per pass, with their direction
    TraceImportSummary summary;
};

/// Radius of the circle the linear axes describe in the run's commands ([MultiTasking] Table 2): the path the
/// programmed feed F is measured on (G94). B-radial LB+RB, B-tangential √(RB²+LB²), C-radial |RC−LB|,
/// C-tangential √(RC²+LB²), B-axial and B-X/Y/Z RB, C-axial and C-X/Y/Z RC.
double linearPathRadius(const BallbarRun& run);

/// Reads one file of `run` with run.capture and checks it against the run; `machine` (if not empty) is checked
/// against a `# machine:` line. Throws InputError naming the file and line.
MeasuredTrace importRunTrace(const std::string& path, const BallbarRun& run, const std::string& machine = "");
/// DIR/<run name>.csv for every run, in order.
std::vector<MeasuredTrace> importRunTraces(const std::string& dir, const std::vector<BallbarRun>& runs,
                                           const std::string& machine = "");

/// A file in cnccomp's own layout without a run to check against (the DBB5 runs): one pass, at least three samples.
MeasuredTrace importTrace(const std::string& path);

}  // namespace cnccomp::io
