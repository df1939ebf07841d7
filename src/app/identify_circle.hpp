#pragma once
// `cnccomp identify` on a plan of ball-bar circles of the linear axes (<circle> runs, ISO 230-4): the route to
// linear_circle_identify.hpp, its printed result, and its reports (JSON, HTML).
#include <string>
#include <utility>
#include <vector>

#include "app/identify_methods.hpp"

namespace cnccomp::cli {

/// Identifies the diagnostics of every circle of the plan (nothing printed, nothing written).
IdentifyOutcome identifyLinearCircles(const IdentifyRequest& r);

/// Prints the test conditions, the ISO 230-4 figures and the ranked diagnostics of every run, and the deviations
/// written.
void printLinearCircles(const LinearCircleIdentification& id);

}  // namespace cnccomp::cli
