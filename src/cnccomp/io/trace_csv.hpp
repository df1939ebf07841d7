#pragma once
// Ball-bar traces: CSV `angle_deg,dL_um`, one file per run. Reading goes through the trace import
// (io/trace_import.hpp: measured layouts, checks against the run); these are the plain entry points.
#include <string>
#include <vector>

#include "cnccomp/ballbar.hpp"

namespace cnccomp::io {

/// A trace in cnccomp's layout without a run to check against (at least three samples).
BallbarTrace readTraceCsv(const std::string& path);
void writeTraceCsv(const std::string& path, const BallbarTrace& trace);
/// The same with the run's metadata as `# key: value` lines (run, test, machine, LB, RB, RC, ZC, start, end, step,
/// feed) that the import checks against the plan, so that a file given to another run is refused.
void writeTraceCsv(const std::string& path, const BallbarTrace& trace, const BallbarRun& run, const std::string& machine);
std::string formatTraceCsv(const BallbarTrace& trace, const BallbarRun* run = nullptr, const std::string& machine = "");

}  // namespace cnccomp::io

namespace cnccomp::io {
/// Reads DIR/<run name>.csv for every run, in order, with the run's capture settings, checked against the run
/// (importRunTraces); a missing file is an InputError naming it. Passes are concatenated.
std::vector<BallbarTrace> readRunTraces(const std::string& dir, const std::vector<BallbarRun>& runs);
}  // namespace cnccomp::io
