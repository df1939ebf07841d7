#pragma once
// Volumetric maps of a report before and after a compensation, shared by the identification and the verification
// report: the default map grid, the workspace poses a TCP controller has an answer for, and the map recomputed with
// the drive commands of a compensation (controllers::AppliedCompensation).
#include <string>
#include <vector>

#include "cnccomp/kinematics.hpp"
#include "cnccomp/volumetric_map.hpp"
#include "controllers/backend.hpp"

namespace cnccomp::app::report {

/// True where the tool axis is (nearly) parallel to a rotary axis: there a TCP controller has no unique answer (any
/// angle of that axis gives the same tool axis) and its model is not a prediction of the machine.
bool singularPose(const Kinematics& nominal, const AxisVector& q);

/// X and Y over their travel (≤ ±200 mm, 21 points); the other linear axes at 0 (or the nearest end of their travel);
/// the rotary axes at 0, or, where that pose is singular, at the first of 30°, 45°, −30°, 60° that is not (and lies in
/// the axis's travel). In the syntax of `cnccomp map --grid`.
std::string defaultMapGrid(const MachineModel& machine);

/// The map of a report: grid, plane of the picture, tool length.
struct MapOptions {
    /// Grid as for `cnccomp map`; empty = defaultMapGrid(machine).
    std::string grid;
    std::string plane = "XY";  ///< as `cnccomp map --plane`
    double toolLength = 0;     ///< mm
};

/// The map of the machine with `deviations` on the options' grid (no compensation).
VolumetricMap uncompensatedMap(const MachineModel& machine, const DeviationSet& deviations, const MapOptions& options);

/// controllers::workspaceSamples(machine, perAxis) less the singular poses.
std::vector<AxisVector> regularWorkspaceSamples(const MachineModel& machine, int perAxis);

/// `before` (a map of the machine with `deviations`) recomputed with the compensation's drive commands: the tool-tip
/// error that machine is left with when the controller drives it (rotation and tilt not evaluated: set to 0).
VolumetricMap compensatedMap(const VolumetricMap& before, const MachineModel& machine, const DeviationSet& deviations,
                             const controllers::AppliedCompensation& compensation, double toolLength);

}  // namespace cnccomp::app::report
