#pragma once
// verify for the sphere runs of a plan: the probing program (generated in memory, its probing targets read
// back by cnccomp's reader) run on the simulated machine without and with the compensation; the recorded positions
// (programmed coordinates, as #5061… give them) fitted per pose with the nominal model; the spread of the sphere centres
// over the poses before and after. A perfect compensation puts every centre on the sphere's true position.
#include "app/verify.hpp"

namespace cnccomp::app {

/// One VerifyRun per sphere run: one pass "poses", displacement = each pose's centre minus the mean centre (table
/// frame), span = largest span of a component (as the R-test's displacements). `model` null = no compensation after.
/// Throws ModelError naming the pose and touch when a probing move misses the sphere.
std::vector<VerifyRun> verifySphereRuns(const MachineModel& machine, const measurement::MeasurementPlan& plan, const Kinematics& simulated,
                                        const controllers::AppliedCompensation& model, postproc::Dialect dialect);

}  // namespace cnccomp::app
