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
//   Backlash: machine parameter MP710.x (iTNC 530 "backlash compensation", mm, −1 .. +1; positive when "the rotary
//     encoder reading is ahead of the table", TNC 426/430 Technical Manual 6.4.1) = β, written as an instruction in the
//     comment after [END] (a table cannot set a machine parameter), as the line mp710Line gives.
#include <string>

#include "cnccomp/laser_positioning.hpp"

namespace cnccomp::controllers::heidenhain {

struct LaserCom {
    std::string name;       ///< e.g. "X.COM"
    std::string text;
    double backlashMm = 0;  ///< MP710
};

/// Backlash files of `emit` (the set's reversal values): the machine-parameter file and its line.
inline constexpr const char* kBacklashFile = "CNCCOMP_BACKLASH.MP";
/// The TNC axis index of MP710.x: X 0, Y 1, Z 2 (axes 1–3 of the TNC's axis order [G: MP10 / CfgAxes]); −1 otherwise.
int tncAxisIndex(const std::string& axisName);
/// "MP710.<index>:<mm, sign and 6 decimals>", e.g. "MP710.0:+0.004000" (the iTNC 530 machine-parameter line [G: the
/// file syntax; TNC 640 / TNC7: MP_backLash of the axis, same value]). The laser route and `emit` write it.
std::string mp710Line(int index, double backlashMm);

/// `column`: 1..3 (the component's translation index + 1); `sign`: see above.
LaserCom heidenhainLaserCom(const LaserPositioningResult& r, int column, double sign, bool referenceForward = true);

}  // namespace cnccomp::controllers::heidenhain
