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
    std::vector<double> nominal, forward, reverse;  ///< mm or deg
    /// Trim at a commanded position: linear interpolation, ends held. LinuxCNC uses the forward column when the
    /// joint moves in +, the reverse column in −; this model has no direction and takes their mean.
    double trim(double position) const;
};

/// The file text; throws ModelError when the table breaks a LinuxCNC rule (lines, order, finite numbers).
std::string formatCompTable(const CompTable& t, const std::string& name);
/// Parses a table strictly: every line three numbers (InputError file:line otherwise — LinuxCNC itself would
/// silently stop reading there), strictly increasing nominals, 2..256 lines.
CompTable parseCompTable(const std::string& text, const std::string& name);

}  // namespace cnccomp::controllers::linuxcnc
