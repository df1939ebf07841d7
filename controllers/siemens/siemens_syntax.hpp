#pragma once
// Sinumerik archive/program files made of system-variable assignments (K3 compensation manual: the CEC and EEC
// table files %_N_NC_CEC_INI / %_N_AX_EEC_INI; a subprogram %_N_..._SPF for kinematic-chain data):
//
//   %_N_NC_CEC_INI          first line: file identifier
//   ; comment               comments start with ';'
//   CHANDATA(1)             channel selector
//   $AN_CEC[0,1]=0.0012     assignment: variable, indices in brackets, value (number, "string" or (AXn))
//   M17                     end of file (subprogram end)
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "cnccomp/error.hpp"

namespace cnccomp::controllers::siemens {

struct Assignment {
    int line = 0;
    std::string variable;              ///< e.g. "$AN_CEC"
    std::vector<std::string> indices;  ///< e.g. {"0", "1"} or {"0", "AX1"}
    std::string value;                 ///< raw text: 0.0012, "AXIS_ROT" (quotes removed), (AX1) (parentheses removed)
    enum class Kind { Number, String, Axis } kind = Kind::Number;
};

struct AssignmentFile {
    std::string path;        ///< for error messages
    std::string identifier;  ///< e.g. "_N_NC_CEC_INI"
    std::vector<Assignment> assignments;
};

/// Parses the file text. Throws InputError(path, line, ...) on anything that is not one of the line forms
/// above, on a missing or different identifier (`expectedIdentifier`, empty = any), or a missing M17.
AssignmentFile parseAssignmentFile(const std::string& path, std::string_view text, std::string_view expectedIdentifier);

/// Index as a whole number ≥ 0, or InputError at the assignment's line.
int indexNumber(const AssignmentFile& f, const Assignment& a, size_t which);
/// Value as a finite number, or InputError.
double numberValue(const AssignmentFile& f, const Assignment& a);
/// Machine axis named AXn → n (≥ 1), or InputError.
int axisNumber(const AssignmentFile& f, const Assignment& a, std::string_view text);

/// Stores a value read from assignment `a`; InputError at its line when the slot was assigned already.
template <class T>
void setOnce(std::optional<T>& slot, T value, const AssignmentFile& f, const Assignment& a) {
    if (slot) throw InputError(f.path, a.line, fmt::format("{} is assigned twice", a.variable));
    slot = std::move(value);
}

}  // namespace cnccomp::controllers::siemens
