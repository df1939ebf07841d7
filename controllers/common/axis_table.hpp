#pragma once
// Equidistant compensation tables over one axis (Siemens CEC/EEC, Fanuc pitch error): choosing a grid over
// an axis' travel, sampling a component error on it, and looking values up the way those controllers do
// (linear interpolation between points, end values held beyond the ends, modulo axes wrapped).
// Positions are in the file's unit: mm for linear axes, degrees for rotary axes.
#include <vector>

#include "cnccomp/machine.hpp"

namespace cnccomp::controllers {

struct EquidistantTable {
    double min = 0;       ///< position of point 0 (mm or deg)
    double step = 1;      ///< spacing (mm or deg)
    bool modulo = false;  ///< the table spans one revolution: values[last] == values[0], positions wrap
    std::vector<double> values;
    double max() const { return min + step * (static_cast<double>(values.size()) - 1); }
    /// Linear interpolation; ends held; a modulo table wraps the position into [min, max).
    double at(double position) const;
};

/// Smallest "nice" step (1, 2, 2.5, 5 × 10^k) not below `x` (> 0).
double niceStepAtLeast(double x);

/// Equidistant points over an axis' travel in file units, at most `maxPoints` (≥ 2) points:
/// a modulo rotary axis gets [0, 360] with a step dividing 360; other axes [floor(min/step)·step,
/// ceil(max/step)·step], always including 0. Throws ModelError for an axis without a finite travel.
EquidistantTable gridOverTravel(const Link& axis, int maxPoints);

/// File unit per internal unit of an axis position (1 for mm, 180/π for rotary axes).
double positionScale(const Link& axis);

}  // namespace cnccomp::controllers
