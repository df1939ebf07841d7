#pragma once
// Every run of a measurement plan as observations for the least-squares engine, reading DIR/<run>.csv for each:
// ball-bar runs (BallbarObservation), absolute ball-bar runs ([FanWuLi]), R-test runs ([Moravek2019] / [RotaryTableModel]) and DBB5
// runs ([IbarakiDBB5]).
#include <string>

#include "cnccomp/identification/observation.hpp"
#include "cnccomp/io/plan_xml.hpp"

namespace cnccomp {

/// Throws InputError naming a missing or malformed trace file, ModelError for an empty plan.
Observations planObservations(const MachineModel& machine, const MeasurementPlan& plan, const std::string& traceDir);

}  // namespace cnccomp
