#pragma once
// LinuxCNC joint compensation table, COMP_FILE_TYPE 1 (LinuxCNC docs/src/config/ini-config.adoc,
// src/emc/motion/usrmotintf.cc): one line per point, "nominal forward-trim reverse-trim", blank separated,
// machine units (mm, deg), nominals strictly increasing, at most 256 lines, no header or comment lines (LinuxCNC
// stops reading at the first line that is not three numbers). The trim is added to the commanded joint position:
// motor_pos_cmd = pos_cmd + trim(pos_cmd), linearly interpolated, end values held beyond the ends.
#include <string>
#include <vector>

namespace cnccomp::controllers::linuxcnc {

inline constexpr int kMaxCompLines = 256;

struct CompTable {
    std::vector<double> nominal, forward, reverse;  ///< mm or deg; trims (type 1 meaning)
    /// The trim LinuxCNC adds at a joint position (control.c compute_screw_comp): the forward column while the joint
    /// moves in + (direction > 0), the reverse column in − (direction < 0); direction 0 = their mean (a model
    /// without the direction). Linear interpolation between lines, the end values held beyond the ends (the table
    /// sits between −DBL_MAX and +DBL_MAX sentinels with zero slope, motion.c), looked up at the raw position.
    double trim(double position, int direction = 0) const;
};

/// The trims of a table read as COMP_FILE_TYPE 0 (columns are actual positions): trim = nominal − column
/// (usrmotintf.cc usrmotLoadComp).
CompTable fromActualPositions(const CompTable& type0);

/// The file text; throws ModelError when the table breaks a LinuxCNC rule (lines, order, finite numbers).
std::string formatCompTable(const CompTable& t, const std::string& name);
/// Parses a table strictly: every line three numbers (InputError file:line otherwise — LinuxCNC itself would
/// silently stop reading there), strictly increasing nominals, 2..256 lines.
CompTable parseCompTable(const std::string& text, const std::string& name);

}  // namespace cnccomp::controllers::linuxcnc
