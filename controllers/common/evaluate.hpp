#pragma once
// Evaluation harness shared by every backend's tests: how much of the volumetric tool-tip error of an erroneous
// machine is left once a controller's compensation is applied. The programmed commands are those meant for the
// nominal machine; the target pose is the nominal forward kinematics, the achieved pose the exact erroneous
// kinematics at the commands the controller sends to the drives (q_drive = comp.driveCommands(q)).
#include <vector>

#include "cnccomp/deviations.hpp"
#include "controllers/backend.hpp"

namespace cnccomp::controllers::common {

/// Tool-tip (and tool-axis) error of the erroneous machine vs the nominal one over a set of programmed axis
/// commands, without and with a controller's compensation applied (q_drive = comp.driveCommandsForTool(q, toolLength),
/// which is comp.driveCommands(q) unless the model uses the tool length).
struct CompensationFigures {
    double maxBefore = 0, maxAfter = 0, rmsBefore = 0, rmsAfter = 0;  ///< mm, tip error
    double maxAxisBefore = 0, maxAxisAfter = 0;                       ///< rad
    int points = 0;
};

CompensationFigures evaluateCompensation(const MachineModel& m, const DeviationSet& truth,
                                         const AppliedCompensation& comp, const std::vector<AxisVector>& programmed,
                                         double toolLength);

/// A grid of programmed commands over the machine's travel (linear axes clamped to ±maxLinear mm around 0, rotary
/// axes over their travel clamped to ±180°), `perAxis` samples per axis (ends included; one sample = the middle).
/// Odd counts include rotary 0° and ±180°, which are singular orientations on many machines (tool axis
/// parallel to a rotary axis): an IK-based compensation model may need to skip them.
std::vector<AxisVector> workspaceSamples(const MachineModel& m, int perAxis, double maxLinear = 200.0);

/// Emits with the backend, writes nothing, reads the files back through backend.apply(), and evaluates.
CompensationFigures emitApplyEvaluate(const Backend& b, const MachineModel& m, const DeviationSet& truth,
                                      const std::vector<AxisVector>& programmed, double toolLength);

/// The identity compensation (drives get the programmed commands): the "before" reference.
class NoCompensation final : public AppliedCompensation {
public:
    AxisVector driveCommands(const AxisVector& programmed) const override { return programmed; }
};

}  // namespace cnccomp::controllers::common
