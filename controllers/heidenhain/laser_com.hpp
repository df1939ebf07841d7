#pragma once
// HEIDENHAIN iTNC 530 compensation value table and backlash of one linear axis from ISO 230-2 laser runs
// (cnccomp/laser_positioning.hpp; table choice and backlash model: controllers/common/laser_axis.hpp).
//   <AXIS>.COM (tnc_table.hpp layout: BEGIN / header / rows / [END]): columns NR, AXISPOS (machine position, mm) and the
//     axis' positioning error column E<axis><axis> (KinematicsComp .COM tables: "AXISPOS column plus error columns
//     (EXX / EAA for positioning)", iTNC 530 HSCI technical manual 07/2013 p.680, ../shared/CONTROLLERS.md), value the
//     positioning error (mm) of the reference-approach direction at the laser's targets (an error column: the control
//     compensates what it lists [G: sign as an error, confirm with KinematicsDesign]); the table is assigned to the axis
//     by a COMPTAB entry of its MachAxis row (<AXIS>.COM:E<axis><axis>) [G].
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

LaserCom heidenhainLaserCom(const LaserPositioningResult& r, bool referenceForward = true);

}  // namespace cnccomp::controllers::heidenhain
