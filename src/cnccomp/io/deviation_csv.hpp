#pragma once
// Deviation files: CSV `name,alias,value,unit[,alias_value]`. A row's value is the value under the symbol in its
// `name` column (or, when that is empty, in its `alias` column): an ISO 230-1 name gives the ISO value (the
// standard's reference axis and sign), a paper alias the paper's value (iso_names.hpp). When a row names both and
// the two differ in meaning (e.g. ISO EC0Y = −gXY), the file must carry `alias_value`, which is then checked.
// Deviations a file does not list are zero under their ISO names (under their aliases when every row uses an
// alias). Component-error coefficients are rows `NAME[k]` (k from 0). Writers put the ISO name and value first,
// lengths in um, angles in arcsec, and the paper alias with its value in `alias`, `alias_value`.
// Reversal values (DeviationSet::reversal, ISO 230-2 mean reversal B̄ of a linear axis) are rows `B<axis>` (BX, BY, BZ),
// no alias, a length (written in um) after the deviations and only when present. "B" after ISO 230-2's symbol B for the
// reversal value; it cannot clash with an ISO 230-1 name (those begin with E: EXX, EB0Z) nor with an axis name (one
// letter). Refused, naming file and line: an axis the machine does not have, a rotary axis, an alias, a unit that is
// not a length, an axis given twice.
#include <string>

#include "cnccomp/deviations.hpp"

namespace cnccomp::io {

DeviationSet readDeviationCsv(const std::string& path, const MachineModel& machine);
/// Writes the present deviations (all of them when `all`), atomically.
void writeDeviationCsv(const std::string& path, const DeviationSet& set, bool all = false);
/// Same text as a string (for printing and tests).
std::string formatDeviationCsv(const DeviationSet& set, bool all = false);

}  // namespace cnccomp::io
