#pragma once
// Ball-bar traces written the way an instrument exports them (the layouts io/trace_import.hpp reads): a simulated
// measurement standing in for the ball bar, e.g. for a demonstration of the whole loop or a test of the import.
#include <string>
#include <vector>

#include "cnccomp/ballbar.hpp"
#include "cnccomp/circular_test.hpp"

namespace cnccomp::io {

/// The passes an instrument records for `run` on `machine`, from run.capture: one pass per direction (default: the
/// step's), each over the sweep extended by the overshoot at both ends, at the plan's step. ModelError when the
/// overshoot leaves the rotary axis' travel (simulateRun's check).
std::vector<DirectedTrace> simulateCapturedPasses(const Kinematics& machine, const BallbarRun& run);

/// The passes as a file in the run's capture layout: its column names and units, decimal comma when capture.decimal
/// is ',' (then ';' separates), a `pass` column (ccw/cw) for two passes, and the run's `# key: value` metadata.
/// `timeSampled`: a time column (t = 0 at the first sample, continuous over the passes, each pass starting at its
/// first sample; needs capture.feed) instead of the angle column.
std::string formatCapturedTrace(const BallbarRun& run, const std::vector<DirectedTrace>& passes, bool timeSampled,
                                const std::string& machine);

/// Appends the capture's column header and the passes' rows (as formatCapturedTrace writes them) to `o`; `omegaDeg` is
/// the sweep rate (deg/s) that turns angle into time when `timeSampled`.
void appendCapturedPasses(std::string& o, const RunCapture& capture, const std::vector<DirectedTrace>& passes,
                          bool timeSampled, double omegaDeg);

}  // namespace cnccomp::io
