#pragma once
// Fanuc stored pitch error compensation and backlash compensation of one linear axis from ISO 230-2 laser runs
// (cnccomp/laser_positioning.hpp; the backlash model and the choice of table: controllers/common/laser_axis.hpp).
//   3620-3624 and the data N1xxxx (pitch_error.hpp, B-63980EN pp.99-100): equidistant points from the reference
//     position (machine 0), the interval the laser's mean target spacing (0.1 mm), the table's curve resampled there
//     (linear between the targets, ends held); data = increments of the correction −(x̄(P) − x̄(0)) in detection
//     units (IS-C 0.0001 mm [G]) × magnification; sign as the emit route (a positive value moves the axis + [G]).
//     x̄(0), the error at the reference position, is a shift of the reference position (parameter 1850, by hand).
//   1851 backlash compensating value (cutting feed) and 1852 (rapid traverse, used with 1800#4 RBK = 1), word axis,
//     detection units (0i-C parameter manual B-64120EN p.116): β of laser_axis.hpp, the same in both (the laser runs
//     are one feed).
// Point numbers from 0 (3620 = the point of the reference position); an axis whose points overlap another axis'
// must be renumbered (3620–3622 are per axis, the data shared) [G].
#include <map>
#include <string>

#include "cnccomp/laser_positioning.hpp"
#include "controllers/fanuc/parameter_file.hpp"
#include "controllers/fanuc/pitch_error.hpp"

namespace cnccomp::controllers::fanuc {

struct LaserPitch {
    PitchTable table;       ///< axis = -1 (the file names the controller axis number)
    long backlash = 0;      ///< 1851 = 1852, detection units
    std::string file;       ///< the parameter file text
};

/// β (µm, controllers/common/set_backlash.hpp) in detection units of `unitMm` (PitchOptions::unit), rounded.
long backlashDetectionUnits(double backlashUm, double unitMm);
/// 1851 (cutting feed) and 1852 (rapid traverse, with 1800#4 RBK) = the detection units of each axis number (A word)
/// of `units`, one axis-type line each (B-64120EN p.116): the laser route and `emit` write backlash with this.
void addBacklashParameters(std::vector<Parameter>& lines, const std::map<int, long>& units);

/// `axisNumber`: the controller's axis number (A word). Throws ModelError when the data do not fit (PitchOptions).
LaserPitch fanucLaserPitch(const LaserPositioningResult& r, int axisNumber, bool referenceForward = true,
                           const PitchOptions& o = {});

}  // namespace cnccomp::controllers::fanuc
