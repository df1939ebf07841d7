#pragma once
// The range of values a deviation can have, checked by the readers of deviation sets (CSV, the generic backend's JSON).
#include <string>

#include "cnccomp/machine.hpp"

namespace cnccomp::io {

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

}  // namespace cnccomp::io
