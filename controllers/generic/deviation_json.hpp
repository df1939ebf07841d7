#pragma once
// The deviation set as JSON (generic backend): every present deviation with its place in the machine (side,
// link, component), its kind, and its value(s) in mm / rad; component errors with their basis.
#include <string>
#include <vector>

#include "cnccomp/deviations.hpp"

namespace cnccomp::controllers::generic {

std::string formatDeviationJson(const DeviationSet& d, const std::vector<std::string>& header, const std::string& source,
                                const std::string& date);
/// Reads it back for a machine: InputError(file:line) on unknown names, a place that contradicts the machine,
/// a wrong number of coefficients, non-numbers.
DeviationSet readDeviationJson(const std::string& text, const std::string& file, const MachineModel& m);

}  // namespace cnccomp::controllers::generic
