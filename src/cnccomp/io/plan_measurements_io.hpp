#pragma once
// Reads the captures of a plan from the folder of its measured runs into one PlanMeasurements
// (measurement/plan_measurements.hpp): DIR/<run>.csv for every run of the kinds asked for, and the probe result file.
// The one place the identification's measurements are read.
#include <string>

#include "cnccomp/machine.hpp"
#include "cnccomp/measurement/plan.hpp"
#include "cnccomp/measurement/plan_measurements.hpp"

namespace cnccomp::io {

/// Reads, in this order, the ball-bar runs (importRunTraces: checked against their runs and `# machine:` lines against
/// machine.name, unit checks over the set), the absolute ball-bar runs, the R-test runs (checked against their poses),
/// the DBB5 runs, the circles of the linear axes (each run validated and its commands checked against the machine
/// first) and the probe result file DIR/<probeLog>. InputError naming the file and line for a file that is missing or
/// does not fit its run.
measurement::PlanMeasurements loadPlanMeasurements(const MachineModel& machine, const measurement::MeasurementPlan& plan, const std::string& dir,
                                      const measurement::MeasurementKinds& kinds, const std::string& probeLog = "cnccomp-probe.txt");

}  // namespace cnccomp::io
