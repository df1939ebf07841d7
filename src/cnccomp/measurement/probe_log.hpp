#pragma once
// The touches a probing program recorded (one result file per plan, io/probe_log.hpp reads and writes it): for every
// touch the pose and touch numbers (from 0, in plan order over every <sphere> run of the plan), whether the probe
// triggered and the axis positions where it did.
#include <string>
#include <vector>

#include "cnccomp/machine.hpp"

namespace cnccomp::measurement {

struct ProbeTouch {
    int pose = 0, touch = 0;  ///< from 0, plan order (pose numbers run on over the plan's sphere runs)
    int triggered = -1;       ///< 1 triggered, 0 missed (the program's flag), -1 the file has no flag
    AxisVector q;             ///< axis positions at the trigger (description frame: mm, rad); axes the file does not
                              ///< give are NaN
    int line = 0;             ///< line in the file
};

struct ProbeLog {
    std::string file;         ///< where it was read from (for messages)
    std::vector<ProbeTouch> touches;
};

}  // namespace cnccomp::measurement
