#pragma once
// Fanuc stored pitch error compensation (parameters 3620-3625 and the compensation data), as the parameter manual
// describes it (Series 0i-PB parameter manual B-63980EN/01, 4. "Description of parameters", 3620-3625, pp. 99-100;
// the 30i manual B-63950EN has the same text):
//   3620 number of the compensation point at the reference position (machine coordinate 0)
//   3621 number of the farthest point on the negative side = 3620 - (negative stroke / interval) + 1
//   3622 number of the farthest point on the positive side = 3620 + (positive stroke / interval)
//   3623 magnification (data x magnification x detection unit), 3624 interval between points (mm / deg)
//   3625 travel per revolution of a rotary axis (360: rotary-axis type)
//   data N(10000 + k)Q0P<integer>: the compensation output for the section that ends at point k, i.e. for the move
//   from machine position (k - 3620 - 1) x interval to (k - 3620) x interval (incremental values; B-63980EN p.100
//   example 1: points 33..49 around reference 40 at 50 mm).
//   Rotary-axis type (p.100 example 2): 3621 = 3620, 3622 = 3620 + 360 / interval; the data of 3620+1 .. 3622 sum to
//   zero over the revolution, and "for compensation position 3620, set the same compensation value as for 3622"
//   (point 3620's section, the last interval before 0 deg, is the one that ends at 360 deg).
// Positions are the controller's machine coordinates (Link::machineZero). Values are in detection units
// (IS-C: 0.0001 mm / 0.0001 deg [G]). The compensation is the correction added to the command (= -positioning error)
// [G: sign]; it is zero at the reference position. The error's own value there is a constant offset of the axis: on a
// linear axis the TCP offsets and 1220 hold it (tcp_parameters.hpp); on a rotary axis it is a zero-position error, which
// no parameter cnccomp writes holds: reported as not compensated.
// The apply model interpolates linearly inside a section [G: the control may output it as a step at the point].
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
    /// Absolute correction (mm / deg) at a machine position (mm / deg), summed from the reference position as the
    /// parameter manual explains: 0 at the reference, + data[k] across the section ending at point k; linear inside a
    /// section, ends held; a rotary-type table wraps.
    double correction(double position, double unit) const;
};

struct PitchPlan {
    std::vector<PitchTable> tables;
    std::vector<Coverage> compensated, notCompensated;
};

/// The positioning error of an axis (the sum of its positioning component errors EXX / ECC ..., along the axis) at a
/// command (internal units), from a flat deviation vector.
double positioningError(const MachineModel& m, const Eigen::VectorXd& values, int axis, double command);

/// Positioning component errors (EXX of X, ECC of C, ...) → tables. Other component errors are reported NOT
/// compensated. Throws ModelError when a limit is exceeded.
PitchPlan pitchFromDeviations(const MachineModel& m, const DeviationSet& d, const PitchOptions& o);

std::vector<Parameter> pitchLines(const MachineModel& m, const std::vector<PitchTable>& tables);

/// InputError (file:line) on inconsistent point numbers, missing data, data of a rotary-type table that do not
/// sum to zero over the revolution or whose reference point's value differs from the last point's.
std::vector<PitchTable> pitchFromFile(const MachineModel& m, const ParameterFile& f);

}  // namespace cnccomp::controllers::fanuc
