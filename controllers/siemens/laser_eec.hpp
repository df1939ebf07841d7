#pragma once
// Sinumerik 840D sl leadscrew / encoder error compensation (EEC) and backlash of one linear axis from ISO 230-2 laser
// runs (cnccomp/laser_positioning.hpp; table choice and backlash model: controllers/common/laser_axis.hpp).
//   AX_EEC.INI (%_N_AX_EEC_INI, K3 compensation manual; layout as compensation_tables.hpp): $AA_ENC_COMP[0,n,AXk] at
//     MIN + n·STEP, MIN = the first target, STEP = the mean target spacing (0.1 mm), MAX = the last point; the value is
//     the axis' positioning error (mm) of the reference-approach direction: "a positive value moves the axis in the
//     negative direction" (808D K3 p.106), so the error itself cancels.
//   AX_LASER_MD.INI: MD32450 $MA_BACKLASH[0,AXk] = β (mm, positive for the usual lost motion: "positive, if the encoder
//     is leading the machine part (normal situation)", SINUMERIK 808D Parameter Manual 08/2013 p.228) and MD32700
//     $MA_ENC_COMP_ENABLE[0,AXk] = 1 — to be loaded after the table: the table loads only while MD32700 = 0 (K3).
#include <string>

#include "cnccomp/laser_positioning.hpp"

namespace cnccomp::controllers::siemens {

struct LaserEec {
    double min = 0, step = 0;          ///< mm
    std::vector<double> values;        ///< mm, $AA_ENC_COMP points
    double backlashMm = 0;             ///< MD32450
    std::string eec, machineData;      ///< file texts
};

/// The MD32450 line of axis `axis` (e.g. "AX1"): "$MA_BACKLASH[0,AX1]=0.004000\n" (mm, 6 decimals; [0] = the first
/// measuring system). The laser route and `emit` write backlash with this.
std::string backlashMachineData(const std::string& axis, double backlashMm);

/// `axis`: the machine axis name in the files, e.g. "AX1". Throws ModelError for more than `maxPoints` points.
LaserEec siemensLaserEec(const LaserPositioningResult& r, const std::string& axis, bool referenceForward = true,
                         int maxPoints = 1000);

}  // namespace cnccomp::controllers::siemens
