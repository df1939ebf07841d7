#pragma once
// A LinuxCNC pitch-error table (COMP_FILE_TYPE 1, comp_table.hpp) from the ISO 230-2 laser positioning runs of one
// axis (cnccomp/laser_positioning.hpp).
//
// Sign. The laser's deviation is x = actual − target (ISO 230-2 clause 2): x > 0 means the slide went too far.
// LinuxCNC adds the trim to the commanded joint position: motor_pos_cmd = pos_cmd + backlash_filt, where
// backlash_filt follows backlash_corr = fwd_trim + fwd_slope·(pos_cmd − nominal) while vel_cmd > 0 and the rev_trim
// line while vel_cmd < 0 (src/emc/motion/control.c, compute_screw_comp and the output loop); with COMP_FILE_TYPE 1 the
// second and third columns are these trims as written (src/emc/motion/usrmotintf.cc, usrmotLoadComp). With the motor
// at P + t the slide reaches P + t + x(P + t) ≈ P + t + x(P) (x changes by a few µm per metre, so the difference
// x(P + t) − x(P) is below 1e-6 µm for trims of µm), so t = −x cancels the deviation: forward trim = −x̄_i↑,
// reverse trim = −x̄_i↓, in mm, at the targets P_i. Example: the axis overshoots by +5 µm at 100 mm → "100 -0.005 …".
// The table holds the reversal as the difference of its columns, so BACKLASH is not needed with it (and LinuxCNC
// ignores BACKLASH on a joint with a COMP_FILE: docs/src/config/ini-config.adoc, [JOINT_n] BACKLASH and COMP_FILE).
// The laser runs must have been measured with the joint's compensation off (no COMP_FILE, BACKLASH = 0); on a machine
// measured with a table active, the new trims are the old ones plus these (not done here).
#include <string>

#include "cnccomp/laser_positioning.hpp"
#include "controllers/linuxcnc/comp_table.hpp"

namespace cnccomp::controllers::linuxcnc {

/// One line per target: nominal P_i (mm), forward trim −x̄_i↑ / 1000, reverse trim −x̄_i↓ / 1000 (mm). Throws
/// ModelError for more than kMaxCompLines targets.
CompTable compTableFromLaser(const LaserPositioningResult& r);

/// The BACKLASH value (mm) that alone (no COMP_FILE) makes the mean reversal vanish: LinuxCNC adds +BACKLASH/2 while
/// moving + and −BACKLASH/2 while moving − (control.c, compute_screw_comp without a table), which raises every B_i by
/// BACKLASH, so BACKLASH = −B̄ / 1000 (B̄ < 0 for the usual lost motion: the slide lags behind the motor).
double backlashFromLaser(const LaserPositioningResult& r);
/// The same from a reversal value B̄ in mm (DeviationSet::reversal: ISO 230-2's B̄ in the laser's frame): −B̄.
inline double backlashFromReversal(double reversalMm) { return -reversalMm; }
/// The comment written beside a negative BACKLASH (B̄ > 0: the slide overshoots on reversal). LinuxCNC 2.9 keeps the sign:
/// inijoint.cc loadJoint reads BACKLASH as a plain double, taskintf.cc emcJointSetBacklash and command.c
/// EMCMOT_SET_JOINT_BACKLASH pass it on unchanged, control.c compute_screw_comp sets backlash_corr = ±0.5·backlash by
/// the direction of motion (no fabs) and ramps backlash_filt towards it with the same S-curve for either sign of the
/// step; motor_pos_cmd = pos_cmd + backlash_filt (output_to_hal). Run on the real LinuxCNC 2.9
/// (tests/linuxcnc/test_linuxcnc_backlash.cpp: BACKLASH = −0.003 mm gives motor-pos-cmd = pos-cmd ∓ 0.0015 mm at rest
/// after +/− motion, as the apply model says).
inline constexpr const char* kNegativeBacklashNote =
    "; negative: the slide overshoots on reversal; LinuxCNC 2.9 applies it with its sign (control.c compute_screw_comp: "
    "+BACKLASH/2 moving +, -BACKLASH/2 moving -; run on the real LinuxCNC 2.9)";

/// The lines the user adds to the INI file for joint `joint` with the table written as `fileName` (to be placed beside
/// the INI file: usrmotintf.cc opens the name as given and scripts/linuxcnc.in runs LinuxCNC in the INI's folder), with
/// the alternative (BACKLASH alone) as a comment.
std::string laserCompIniLines(const LaserPositioningResult& r, int joint, const std::string& fileName);

}  // namespace cnccomp::controllers::linuxcnc
