#pragma once
// Equidistant compensation tables over one axis (Siemens CEC/EEC, Fanuc pitch error): choosing a grid over
// an axis' travel, sampling a component error on it, and looking values up the way those controllers do
// (linear interpolation between points, end values held beyond the ends, modulo axes wrapped).
// Positions are in the file's unit (mm for linear axes, degrees for rotary axes) and in the controller's machine
// coordinates: position p is the description's command p + Link::machineZero (commandOf).
#include <vector>

#include "cnccomp/machine.hpp"

namespace cnccomp::controllers::common {

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

/// Equidistant points over an axis' travel in the controller's coordinates (travel − machineZero), file units, at
/// most `maxPoints` (≥ 2) points: a modulo rotary axis gets [0, 360] with a step dividing 360; other axes
/// [floor(min/step)·step, ceil(max/step)·step], always including 0 (the controller's machine zero). Throws ModelError
/// for an axis without a finite travel.
EquidistantTable gridOverTravel(const Link& axis, int maxPoints);

/// File unit per internal unit of an axis position (1 for mm, 180/π for rotary axes).
double positionScale(const Link& axis);

/// The description's command (internal units) of a controller position in file units: p / scale + machineZero.
double commandOf(const Link& axis, double filePosition);

}  // namespace cnccomp::controllers::common
