#pragma once
// Ball-bar traces: CSV `angle_deg,dL_um`, one file per run.
#include <string>
#include <vector>

#include "cnccomp/ballbar.hpp"

namespace cnccomp {

BallbarTrace readTraceCsv(const std::string& path);
void writeTraceCsv(const std::string& path, const BallbarTrace& trace);

}  // namespace cnccomp

namespace cnccomp {
/// Reads DIR/<run name>.csv for every run, in order; a missing file is an InputError naming it.
std::vector<BallbarTrace> readRunTraces(const std::string& dir, const std::vector<BallbarRun>& runs);
}  // namespace cnccomp
