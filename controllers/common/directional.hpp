#pragma once
// A controller model whose compensation depends on the direction each axis moves in (backlash, two-column tables):
// implemented besides controllers::AppliedCompensation by the models that hold such values (LinuxCNC BACKLASH and the
// COMP_FILE columns, Fanuc 1851, Sinumerik MD32450, HEIDENHAIN MP710, ISG getriebe[0].lose; the ideal compensation of a
// set with reversal values). `cnccomp verify` asks for it along the test programs' passes (dynamic_cast); a model
// without it is direction-free.
#include "cnccomp/machine.hpp"

namespace cnccomp::controllers::common {

class DirectionalCompensation {
public:
    virtual ~DirectionalCompensation() = default;
    /// The drive commands for a pose the program reaches with each axis' command moving in `motion` (per axis,
    /// description order: +1, −1, or 0 = not known / at rest since the start, cnccomp/lost_motion.hpp
    /// motionDirections); 0 gives the mean of the two sides. Otherwise as AppliedCompensation::driveCommandsForTool.
    virtual AxisVector driveCommandsMoving(const AxisVector& programmed, double toolLength, const AxisVector& motion) const = 0;
};

}  // namespace cnccomp::controllers::common
