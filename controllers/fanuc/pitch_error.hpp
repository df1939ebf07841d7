#pragma once
// Fanuc stored pitch error compensation (parameters 3620-3625 and the compensation data):
//   3620 number of the compensation point at the reference position (machine coordinate 0 [G])
//   3621 number of the point at the most negative end, 3622 at the most positive end
//   3623 magnification (data x magnification x detection unit), 3624 interval between points (mm / deg)
//   3625 travel per revolution of a rotary axis (360 = rotary-axis type: one revolution, data sum to zero)
//   data N(10000 + point)Q0P<integer>: the compensation added over the interval that ends at that point
//   (incremental), in detection units (IS-C: 0.0001 mm / 0.0001 deg [G]).
// The compensation is the correction added to the command (= -positioning error) [G: sign]; it is zero at the
// reference position, so the error's own value there is reported as not compensated. The apply model
// interpolates linearly inside an interval [G: the control may output it as a step at the point].
#include <string>
#include <vector>

#include "cnccomp/deviations.hpp"
#include "controllers/backend.hpp"
#include "controllers/fanuc/parameter_file.hpp"

namespace cnccomp::controllers::fanuc {

struct PitchOptions {
    int maxIntervals = 128;   ///< per axis [G]
    int maxPoints = 1024;     ///< compensation points of all axes together (0..1023) [G]
    int maxData = 127;        ///< |data| per point before magnification [G]
    int maxMagnification = 100;
    double unit = 1e-4;       ///< detection unit (mm or deg), IS-C [G]
};

struct PitchTable {
    int axis = -1;            ///< machine axis index
    int reference = 0, negative = 0, positive = 0;
    int magnification = 1;
    double interval = 1;      ///< mm / deg
    bool rotaryType = false;  ///< 3625 = 360
    std::vector<long> data;   ///< points negative..positive
    /// Cumulative correction (mm / deg) at a position (mm / deg), linear between points, ends held,
    /// a rotary-type table wraps.
    double correction(double position, double unit) const;
    double positionOf(int point) const { return (point - reference) * interval; }
};

struct PitchPlan {
    std::vector<PitchTable> tables;
    std::vector<Coverage> compensated, notCompensated;
};

/// Positioning component errors (EXX of X, ECC of C, ...) → tables. Other component errors are reported NOT
/// compensated. Throws ModelError when a limit is exceeded.
PitchPlan pitchFromDeviations(const MachineModel& m, const DeviationSet& d, const PitchOptions& o);

std::vector<Parameter> pitchLines(const MachineModel& m, const std::vector<PitchTable>& tables);

/// InputError (file:line) on inconsistent point numbers, missing data, data of a rotary-type table that do not
/// sum to zero over the revolution.
std::vector<PitchTable> pitchFromFile(const MachineModel& m, const ParameterFile& f);

}  // namespace cnccomp::controllers::fanuc
