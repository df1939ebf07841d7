#pragma once
// The INI and HAL fragments and the work-offset program of the LinuxCNC backend, and their readers (what the apply
// model takes from them).
#include <array>
#include <map>
#include <optional>
#include <string>

#include "controllers/linuxcnc/trt_kins.hpp"

namespace cnccomp::controllers::linuxcnc {

/// What the INI fragment says: the kinematics module, its joint letters, and per joint the table file.
struct IniFragment {
    std::string kinematics;    ///< module name
    std::string coordinates;   ///< joint letters of the KINEMATICS line's coordinates=, e.g. XYZAC (may be empty)
    std::string trajCoordinates;  ///< [TRAJ] COORDINATES (may be empty)
    int joints = 0;            ///< [KINS] JOINTS (0 when not given)
    std::map<int, std::string> compFile;  ///< joint number → COMP_FILE
    std::map<int, int> compType;          ///< joint number → COMP_FILE_TYPE (0 when not given, as inijoint.cc)
    /// joint number → [JOINT_n] BACKLASH (mm or deg): LinuxCNC adds +BACKLASH/2 while the joint's command moves +,
    /// −BACKLASH/2 while it moves −, and keeps the last while it rests, on a joint without COMP_FILE (control.c
    /// compute_screw_comp; docs/src/config/ini-config.adoc: a COMP_FILE joint ignores BACKLASH).
    std::map<int, double> backlash;
};

/// Parses `[SECTION]`, `KEY = value`, '#' / ';' comments. InputError(file:line) on anything else, on a
/// COMP_FILE_TYPE other than 0 or 1, on a BACKLASH that is not a number, on a JOINTS that is not a count, when no KINEMATICS line is there.
IniFragment parseIni(const std::string& text, const std::string& name);

/// The `setp <module>.<pin> <value>` lines of a HAL fragment; `net`/`loadrt`/comments ignored, anything else an error.
/// Unknown pins of the module are errors. Returns nullopt when the fragment sets no pin.
std::optional<TrtPins> parseHal(const std::string& text, const std::string& name, const std::string& module);

/// The longest program line LinuxCNC 2.9 reads, without its line end: the interpreter reads a line with
/// fgets(raw_line, LINELEN = 255) and aborts the program with "Command too long" when the line fills the buffer
/// (strlen == LINELEN − 1 = 254, the '\n' included; src/emc/rs274ngc/interp_read.cc read_text, src/emc/linuxcnc.h).
inline constexpr size_t kMaxProgramLine = 252;

/// The text with every line longer than `width` characters that starts with `prefix` (a comment) broken at blanks
/// into several lines, each starting with `prefix` and two more blanks on the continuation lines. Other lines as they are.
std::string wrapCommentLines(const std::string& text, const std::string& prefix, size_t width = 200);

/// The work offset a program sets with `G10 L2 P1 X… Y… Z…` (G54, mm); ';' and '(…)' comments, blank lines and M2
/// allowed, anything else an error. InputError when no G10 L2 P1 line is there.
std::array<double, 3> parseWorkOffset(const std::string& text, const std::string& name);

}  // namespace cnccomp::controllers::linuxcnc
