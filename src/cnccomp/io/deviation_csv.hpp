#pragma once
// Deviation files: CSV `name,alias,value,unit[,alias_value]`. A row's value is the value under the symbol in its
// `name` column (or, when that is empty, in its `alias` column): an ISO 230-1 name gives the ISO value (the
// standard's reference axis and sign), a paper alias the paper's value (iso_names.hpp). When a row names both and
// the two differ in meaning (e.g. ISO EC0Y = −gXY), the file must carry `alias_value`, which is then checked.
// Deviations a file does not list are zero under their ISO names (under their aliases when every row uses an
// alias). Component-error coefficients are rows `NAME[k]` (k from 0). Writers put the ISO name and value first,
// lengths in um, angles in arcsec, and the paper alias with its value in `alias`, `alias_value`.
#include <string>

#include "cnccomp/deviations.hpp"

namespace cnccomp {

/// The largest deviation a machine tool can have, checked at reading (a value beyond it is a unit or typing mistake:
/// 1e200 mm made `simulate` crash in the circle fit). A length (location error or component-error coefficient):
/// 100 mm; an angle: 1° (3600 arcsec). Why these bounds: geometric errors of a machine in service are µm to tens
/// of µm and arcseconds (ISO 230-1 tolerances; the deviation sets of the seed papers are below 0.1 mm and 100 arcsec);
/// a mislocated rotary axis after a crash or a wrong machine zero reaches millimetres and a fraction of a degree. A
/// ball bar measures ±1 mm of length change at most (Renishaw QC20-W travel [G]), so no deviation it can identify
/// comes near either bound; beyond them the machine's nominal description is wrong, not its calibration.
inline constexpr double kMaxDeviationLength = 100.0;  ///< mm
inline constexpr double kMaxDeviationAngle = kDeg;     ///< rad (1°)
/// Why `value` (internal units: mm or rad) cannot be a value of deviation `d` (beyond the bounds above, or not
/// finite), or an empty string.
std::string deviationRangeProblem(const DeviationDef& d, double value);

DeviationSet readDeviationCsv(const std::string& path, const MachineModel& machine);
/// Writes the present deviations (all of them when `all`), atomically.
void writeDeviationCsv(const std::string& path, const DeviationSet& set, bool all = false);
/// Same text as a string (for printing and tests).
std::string formatDeviationCsv(const DeviationSet& set, bool all = false);

}  // namespace cnccomp
