#pragma once
// The ISO 230-2 figures of one axis as a console table and as JSON (schema "cnccomp-laser-positioning/1"), the
// output of `cnccomp laser`. Symbols and definitions: ISO 230-2:2014 clause 2, as listed in laser_positioning.hpp
// (↑ forward = approach in the positive direction, ↓ reverse). All deviations µm, targets mm.
#include <string>

#include "cnccomp/laser_positioning.hpp"

namespace cnccomp::io {

/// Per target P_i, x̄_i↑, x̄_i↓, x̄_i, B_i, R_i↑, R_i↓, R_i; then E, E↑, E↓, A, A↑, A↓, B, B̄, R, R↑, R↓, M; the run count and
/// whether environment compensation was done (`environmentStated` false: "not stated in the file").
std::string formatLaserTable(const LaserPositioningResult& r, bool environmentStated);
/// The same fields as JSON; `file` names the laser file.
std::string formatLaserJson(const LaserPositioningResult& r, bool environmentStated, const std::string& file);

}  // namespace cnccomp::io
