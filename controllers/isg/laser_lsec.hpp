#pragma once
// ISG / Beckhoff TwinCAT CNC leadscrew error compensation (LSEC, "SSFK") of one linear axis from ISO 230-2 laser runs
// (cnccomp/laser_positioning.hpp), as the axis' compensation value list (Beckhoff infosys TF5200 "Axis compensation",
// "Leadscrew error compensation (kw.ssfk.*)" and "Example - Non-equidistant bilateral SSFK"):
//   kopf.achs_nr, kopf.log_achs_name; kw.ssfk.interval 0 (non-equidistant: every point's setpoint given),
//   kw.ssfk.kw_startpos, kw.ssfk.kw_nr_max (entries), kw.ssfk.unit 1, kw.ssfk.bilateral 1 (a table per direction),
//   kw.ssfk.table[i].setpoint, .pos, .neg in 0.1 µm (the vendor example's unit: setpoint −200000 = −20 mm; −102 ×
//   0.1 µm), compensation value Δs_i = s_ist,i − s_soll,i (actual − setpoint, the vendor's formula = the ISO 230-2
//   deviation): .pos = x̄_i↑, .neg = x̄_i↓ at the laser's own targets.
// Bilateral LSEC compensates the backlash too ("additional backlash compensation is therefore not necessary"): the
// axis parameters (P-AXIS-00175 lr_param.ssfk = 1, P-AXIS-00021 lr_param.anwahl_losekomp = 0) are printed as lines
// for the axis parameter list. [G]: kw.ssfk.unit = 1 meaning 0.1 µm is read from the example, not from a definition.
#include <string>

#include "cnccomp/laser_positioning.hpp"

namespace cnccomp::controllers::isg {

/// The head lines of an axis' lists: kopf.achs_nr and kopf.log_achs_name (the LSEC list's and the backlash list's).
std::string isgAxisHead(int axisNumber, const std::string& axisName);

/// The backlash of one axis as lines of its axis parameter list (Beckhoff TF5200 "Axis compensation", backlash
/// compensation): P-AXIS-00021 lr_param.anwahl_losekomp 1 ("last axis motion occurred in pos. direction": the
/// reference approach in +, controllers/common/set_backlash.hpp) and P-AXIS-00103 getriebe[0].lose = β in 0.1 µm
/// (SGN16; "0 < backlash: backlash between drive and slide", the usual lost motion) [G: gear stage 0 of the axis]; with
/// the head lines. `emit` writes it for the set's reversal values. ModelError beyond the SGN16 range.
std::string isgAxisBacklash(int axisNumber, const std::string& axisName, double backlashUm);

/// `axisNumber`: kopf.achs_nr; `axisName`: kopf.log_achs_name.
std::string isgLaserLsec(const LaserPositioningResult& r, int axisNumber, const std::string& axisName);

}  // namespace cnccomp::controllers::isg
