#pragma once
// The compensation a TCP-based controller computes: axis commands at which its (erroneous) machine model puts the
// tool at the nominal pose. Gauss–Newton with a truncated-SVD step, so that at singular orientations (tool axis
// parallel to a rotary axis) the unreachable part is left alone instead of sending an axis far away. The step is
// the pseudo-inverse truncated at 1e-4 of the largest singular value (through the eigen-decomposition of JᵀJ).
#include "cnccomp/inverse_kinematics.hpp"

namespace cnccomp::controllers {

/// Commands near `start` at which `actual` reaches `target` (tip in mm, axis weighted by `axisWeight` mm/rad).
/// No allocation.
AxisVector compensatedCommands(const Kinematics& actual, const ToolPose& target, const Vec3& tipInToolFrame,
                               const AxisVector& start, int iterations = 6, double axisWeight = 100.0);

}  // namespace cnccomp::controllers
