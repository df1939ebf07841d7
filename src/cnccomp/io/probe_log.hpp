#pragma once
// The result file of a probing program (cnccomp testprog on a <sphere> plan), one per plan: one line per touch,
//     TOUCH <pose> <touch> <flag> <X> <Y> <Z> <A> <B> <C>
// pose and touch whole numbers from 0 in plan order; flag 1 = the probe triggered, 0 = it did not (a missed touch);
// X Y Z in mm, A B C in degrees, the positions at the trigger in the program's coordinates (the machine coordinates:
// the programs set the work offset to zero). LinuxCNC writes it with (LOG,...) from #5070 and #5061–#5066 (six
// decimals); the Fanuc, Sinumerik and HEIDENHAIN programs write the same words (their number formats: "3." and
// leading blanks are accepted). A line without the flag (9 words) is read as flag unknown: the reader then treats a
// touch at the end of its probing move as missed (identification/sphere_probe.hpp, checkedTouches). Lines that do not
// start with TOUCH are skipped (a controller's own headers); a TOUCH line that is not of this form is an error naming
// the file and line.
#include <string>

#include "cnccomp/machine.hpp"
#include "cnccomp/measurement/probe_log.hpp"

namespace cnccomp::io {

/// Reads the file; axis values go to the machine's axes of the same names (others stay NaN). Throws InputError
/// (file:line) for a malformed TOUCH line, a file that cannot be read or one without any TOUCH line.
measurement::ProbeLog readProbeLog(const std::string& path, const MachineModel& machine);
/// Parses text already read (`source` names it in messages).
measurement::ProbeLog parseProbeLog(const std::string& text, const std::string& source, const MachineModel& machine);
/// The text LinuxCNC's (LOG,...) lines of the probing program give, with `decimals` digits (LinuxCNC: 6).
std::string formatProbeLog(const measurement::ProbeLog& log, const MachineModel& machine, int decimals = 6);
/// formatProbeLog into `path`, atomically.
void writeProbeLog(const std::string& path, const measurement::ProbeLog& log, const MachineModel& machine, int decimals = 6);

}  // namespace cnccomp::io
