#pragma once
// The INI and HAL fragments of the LinuxCNC backend, and their readers (what the apply model takes from them).
#include <map>
#include <optional>
#include <string>

#include "controllers/linuxcnc/trt_kins.hpp"

namespace cnccomp::controllers::linuxcnc {

/// What the INI fragment says: the kinematics module, its joint letters, and per joint the table file.
struct IniFragment {
    std::string kinematics;    ///< module name
    std::string coordinates;   ///< joint letters, e.g. XYZAC
    std::map<int, std::string> compFile;  ///< joint number → COMP_FILE
    std::map<char, bool> wrapped;         ///< axis letter → WRAPPED_ROTARY
};

/// Parses `[SECTION]`, `KEY = value`, '#' / ';' comments. InputError(file:line) on anything else, on a
/// COMP_FILE_TYPE other than 1, on a KINEMATICS line without coordinates=.
IniFragment parseIni(const std::string& text, const std::string& name);

/// The `setp <module>.<pin> <value>` lines of a HAL fragment; `net`/`loadrt`/comments ignored, anything else an error.
/// Unknown pins of the module are errors. Returns nullopt when the fragment sets no pin.
std::optional<TrtPins> parseHal(const std::string& text, const std::string& name, const std::string& module);

}  // namespace cnccomp::controllers::linuxcnc
