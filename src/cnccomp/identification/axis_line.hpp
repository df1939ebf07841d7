#pragma once
// From a measured rotary-axis line (a point and a direction in the bed frame) to the location errors of that axis
// in the machine model (ISO 230-1 position and orientation of the axis line, "POPPE" of the R-test location fits, DBB5 Table 1).
#include <vector>

#include "cnccomp/deviations.hpp"

namespace cnccomp::identification {

/// Sets the location deviations of rotary axis `axis` listed in `only` (indices into machine.deviations) so that
/// the axis line passes through `pointBed` along `dirBed`, both in the bed frame with the links before the axis at
/// their nominal pose for commands `q`. Translation: where the line crosses the plane through the joint origin
/// normal to the nominal direction; rotation: the smallest one turning the nominal direction onto the measured
/// one (perpendicular to the axis; the zero-position error about the axis itself is not observable this way).
/// Exact (no small-angle truncation). Throws ModelError for a non-rotary axis or a direction ⟂ the axis.
void setAxisLine(const MachineModel& m, DeviationSet& set, int axis, const AxisVector& q, const Vec3& pointBed,
                 const Vec3& dirBed, const std::vector<int>& only);

}  // namespace cnccomp::identification
