#pragma once
// HEIDENHAIN iTNC 530 KinematicsComp table and backlash of one linear axis from ISO 230-2 laser runs
// (cnccomp/laser_positioning.hpp; table choice and backlash model: controllers/common/laser_axis.hpp).
//   <AXIS>.COM (tnc_table.hpp layout: BEGIN / header / rows / [END]): columns NR, AXISPOS (machine position, mm, the
//     laser's targets) and C<k>, the column of the axis' positioning component (iTNC 530 HSCI technical manual 07/2013,
//     KinematicsComp, p.680: AXISPOS plus error columns C1–C6), written exactly as `cnccomp emit --controller
//     heidenhain-tnc` writes that component (kinematics_table.cpp): the link's error value, negated on the tool side
//     (tool-side rows are the inverse transforms [G: confirm with KinematicsDesign]); the link's error is the laser's
//     error of the reference-approach direction over the machine's reading sensitivity (laser_deviation.hpp), so the
//     caller passes `column` and `sign` = (tool side ? −1 : +1) / sensitivity. Assigned to the axis by the COMPTAB entry
//     <AXIS>.COM:C<k> of its MachAxis row.
//   Backlash: machine parameter MP710.x (iTNC 530 "backlash compensation", mm) = β [G], written as an instruction in the
//     comment after [END] (a table cannot set a machine parameter).
#include <string>

#include "cnccomp/laser_positioning.hpp"

namespace cnccomp::controllers::heidenhain {

struct LaserCom {
    std::string name;       ///< e.g. "X.COM"
    std::string text;
    double backlashMm = 0;  ///< MP710
};

/// `column`: 1..3 (the component's translation index + 1); `sign`: see above.
LaserCom heidenhainLaserCom(const LaserPositioningResult& r, int column, double sign, bool referenceForward = true);

}  // namespace cnccomp::controllers::heidenhain
