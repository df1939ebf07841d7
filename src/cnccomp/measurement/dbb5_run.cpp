#include "cnccomp/measurement/dbb5_run.hpp"

#include <cmath>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/measurement/sweep.hpp"

namespace cnccomp::measurement {

void Dbb5Run::validate() const {
    const auto bad = [&](const std::string& what) { throw ModelError(fmt::format("DBB5 run '{}': {}", name, what)); };
    for (double v : {LB, toolLength, startDeg, endDeg, stepDeg, setupDeg, coneTiltDeg, toolAngleDeg, barAngleDeg})
        if (!std::isfinite(v)) bad("geometry values must be finite numbers");
    if (!ball.allFinite()) bad("the ball position must be finite");
    if (!(LB > 0)) bad("bar length LB must be positive");
    if (stepDeg == 0) bad("angle step must not be zero");
    if ((endDeg - startDeg) / stepDeg < 0) bad("angle step points away from the end angle");
    if (std::abs((endDeg - startDeg) / stepDeg) > 1e7) bad("more than 10 million samples");
    for (const auto& [axisName, value] : hold)
        if (!std::isfinite(value)) bad(fmt::format("held position of {} must be finite", axisName));
    if (kind == Kind::LinearCircle) {
        if (plane != "XY" && plane != "YZ" && plane != "ZX" && plane != "YX" && plane != "ZY" && plane != "XZ")
            bad(fmt::format("plane '{}' is not XY, YZ or ZX", plane));
    } else if (kind == Kind::RotaryCircle) {
        if (!barDirection.allFinite() || barDirection.norm() < 1e-9) bad("bar direction must be a non-zero vector");
        if (axis.empty()) bad("a rotary circle needs the turning axis");
    } else {
        if (!(toolAngleDeg >= 0 && toolAngleDeg < 90)) bad("tool angle must be in [0, 90) deg");
        if (!(barAngleDeg > 0 && barAngleDeg < 180)) bad("bar angle must be in (0, 180) deg");
        if (!(std::abs(coneTiltDeg) < 90)) bad("cone tilt must be within ±90 deg");
    }
}

std::vector<double> Dbb5Run::anglesDeg() const {
    validate();
    return sweepAnglesDeg(startDeg, endDeg, stepDeg);
}

std::pair<Vec3, Vec3> Dbb5Run::planeAxes() const {
    const auto unit = [](char c) { return Vec3::Unit(c == 'X' ? 0 : c == 'Y' ? 1 : 2); };
    return {unit(plane[0]), unit(plane[1])};
}

}  // namespace cnccomp::measurement
