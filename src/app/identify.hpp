#pragma once
// Identification as a library: the machine's deviations from a measurement plan and its measured runs, in one call.
// `cnccomp identify` is a thin layer over it (src/cli/cmd_identify.cpp: parse → options → identify() → write the files
// with identify_outputs.hpp → print); tests call both directly.
//
// The steps, in order (each fails with a ModelError / InputError naming what does not fit, before the next):
//   1. the options alone (validateOptions, identify_options.hpp; as Ceres' Solver::Options::IsValid), then the bounds
//      against the machine;
//   2. the method: the plan's kind (classifyPlan, or options.measure) looked up in the registry
//      (identify_registry.hpp), which checks the options against the machine and the plan;
//   3. the plan's captures the method reads, read once (io/plan_measurements_io.hpp);
//   4. the method, on them; its result in an IdentificationSummary with a brief and a full report
//      (identify_summary.hpp). Nothing is printed or written.
#include "app/identify_options.hpp"
#include "app/identify_summary.hpp"
#include "cnccomp/machine.hpp"
#include "cnccomp/measurement/plan.hpp"

namespace cnccomp::app {

/// `plan` may be null only for the ball-bar formulas on an eccentricity table (options.eccentricities).
IdentificationSummary identify(const MachineModel& machine, const measurement::MeasurementPlan* plan,
                               const IdentificationOptions& options);

}  // namespace cnccomp::app
