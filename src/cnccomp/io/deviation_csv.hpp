#pragma once
// Deviation files: CSV `name,alias,value,unit`. Readers accept the ISO name or the paper alias in either
// column; component-error coefficients are rows `NAME[k]` (k from 0). Writers put lengths in um, angles in arcsec.
#include <string>

#include "cnccomp/deviations.hpp"

namespace cnccomp {

DeviationSet readDeviationCsv(const std::string& path, const MachineModel& machine);
/// Writes the present deviations (all of them when `all`), atomically.
void writeDeviationCsv(const std::string& path, const DeviationSet& set, bool all = false);
/// Same text as a string (for printing and tests).
std::string formatDeviationCsv(const DeviationSet& set, bool all = false);

}  // namespace cnccomp
