#pragma once
// Lost motion of the linear axes at their reversals along a sequence of commands: what the deviation set's reversal
// values (DeviationSet::reversal, ISO 230-2:2014 mean reversal value B̄) do to a path, and the direction of motion a
// controller's backlash compensation keys on.
//
// Model: the step model of the ball-bar circle's backlash (linear_circle_model.hpp: a step b of the axis' actual
// position when its command reverses, b > 0 the slide lagging; the circle identification reports B̄ = −b), written
// per sample as
//     actual = command + (B̄/2)·s,   s = +1 while the command moves +, −1 while it moves −, 0 before it has moved,
// so that the deviation reached moving + minus the one reached moving − is B̄ (ISO 230-2's B_i = x̄_i↑ − x̄_i↓) and a
// reversal steps the actual position by −B̄ = b against the new motion, as the circle model's step. The offset is in
// the axis' command coordinate, which is the laser's frame of B̄ (a unit command moves the tool by a unit along the
// axis' motion relative to the workpiece, DeviationSet::reversal), so it applies to table and tool slides alike.
// A slide at rest keeps the side of its last motion (the same rule as LinuxCNC's backlash compensation, control.c
// compute_screw_comp: "not moving, use whatever was there before"); the samples before an axis' first motion take
// that motion's direction (the axis is taken to arrive moving the way it leaves: a first sample exactly at a reversal
// is taken on the wrong side, as a circle's pass that starts at a reversal does not show that reversal); an axis that
// never moves gets 0 (no offset: the mean of its two sides).
// [G] one value per axis: a reversal that depends on the position (B_i − B̄) and the transient of the reversal (the
// circle's reversal spike) are not in the set and not modelled.
#include <vector>

#include "cnccomp/deviations.hpp"

namespace cnccomp {

/// Per sample and axis the direction of motion s (+1, −1; 0: the axis never moves) along `commands` (above). A change of at
/// most `restMm` (mm or rad) counts as rest.
std::vector<AxisVector> motionDirections(const std::vector<AxisVector>& commands, double restMm = 1e-9);

/// The axes' actual positions for `commands` reached with `directions` on a machine with the reversal values of
/// `d`: command + (B̄/2)·s per axis with a reversal value (others unchanged).
AxisVector withLostMotion(const DeviationSet& d, const AxisVector& commands, const AxisVector& directions);

/// The same along a whole sequence (directions from motionDirections).
std::vector<AxisVector> withLostMotion(const DeviationSet& d, const std::vector<AxisVector>& commands);

}  // namespace cnccomp
