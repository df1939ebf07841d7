#pragma once
// Every run of a measurement plan as observations for the least-squares engine, from its captures read once
// (measurement/plan_measurements.hpp, io/plan_measurements_io.hpp):
// ball-bar runs (BallbarObservation), absolute ball-bar runs ([FanWuLi]), R-test runs ([Moravek2019] / [RotaryTableModel]) and DBB5
// runs ([IbarakiDBB5]).
#include <string>

#include "cnccomp/identification/observation.hpp"
#include "cnccomp/measurement/plan.hpp"
#include "cnccomp/measurement/plan_measurements.hpp"

namespace cnccomp::identification {

/// `data` holds the captures of every kind of run the plan has (MeasurementKinds::observed()). ModelError for an empty
/// plan.
Observations planObservations(const MachineModel& machine, const measurement::MeasurementPlan& plan, const measurement::PlanMeasurements& data);

}  // namespace cnccomp::identification
