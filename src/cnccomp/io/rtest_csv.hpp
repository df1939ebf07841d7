#pragma once
#include <iosfwd>
// R-test traces: CSV `pose,<axis>_mm|<axis>_deg …,dx_um,dy_um,dz_um`, one file per run: the axis commands of every
// pose (linear axes in mm, rotary axes in degrees, machine axis order) and the displacement of the ball centre from
// the nest centre in the tool (sensor) frame, µm.
#include <string>
#include <vector>

#include "cnccomp/identification/rtest_run.hpp"

namespace cnccomp::io {

/// Throws InputError (file:line) for a missing column or file, a non-finite value, or fewer than three poses.
identification::RtestTrace readRtestCsv(const std::string& path, const MachineModel& machine);
void writeRtestCsv(const std::string& path, const MachineModel& machine, const identification::RtestTrace& trace);
/// The same CSV written to a stream (for outputs staged together, io/output_set.hpp).
void writeRtestCsv(std::ostream& out, const MachineModel& machine, const identification::RtestTrace& trace);

/// Reads DIR/<run>.csv for every run and checks each file against the plan: the same number of poses and the
/// same commands (to 1e-5 mm / deg; the plan's exact commands are kept). Errors name the file and line.
std::vector<identification::RtestTrace> readRtestTraces(const std::string& dir, const MachineModel& machine,
                                        const std::vector<measurement::RtestRun>& runs);

}  // namespace cnccomp::io
