#include "controllers/common/laser_axis.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "controllers/common/set_backlash.hpp"

namespace cnccomp::controllers::common {

LaserAxisCompensation laserAxisCompensation(const LaserPositioningResult& r, bool referenceForward) {
    LaserAxisCompensation c;
    c.referenceForward = referenceForward;
    for (const LaserTargetResult& t : r.targets) {
        c.positions.push_back(t.target);
        c.forwardUm.push_back(t.meanForward);
        c.reverseUm.push_back(t.meanReverse);
        c.referenceUm.push_back(referenceForward ? t.meanForward : t.meanReverse);
        c.backlashLeftUm = std::max(c.backlashLeftUm, std::abs(t.reversal - r.meanReversal));
    }
    c.backlashUm = backlashFromMeanReversalUm(r.meanReversal);
    return c;
}

std::string servoMismatchNote(const std::string& gainParameter) {
    return fmt::format(
        "servo mismatch (ball-bar circle, ms) is not a table value: it is the difference of the interpolating axes' "
        "position-loop gains (lag 1/kv); set the axes of a plane to the same kv ({}), raising the gain of the lagging "
        "axis or lowering the leading one's, and repeat the circle",
        gainParameter);
}

}  // namespace cnccomp::controllers::common
