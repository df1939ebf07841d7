#pragma once
// Strict number parsing and atomic file writing shared by every reader and writer.
#include <functional>
#include <iosfwd>
#include <optional>
#include <string>
#include <string_view>

namespace cnccomp {

/// Whole-string number ("1.5", "-2e-3", "inf", "-inf"); no trailing junk. NaN text is rejected.
std::optional<double> parseNumber(std::string_view s);
/// Trim ASCII white space.
std::string_view trim(std::string_view s);

/// Writes through `write` into a temporary file beside `path`, then renames it over `path`.
/// A failure leaves no half file. Refuses to write onto any of `inputs` (the program never overwrites an input).
void writeFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write);
/// Throws InputError if `output` names the same file as one of the inputs.
void refuseToOverwrite(const std::string& output, std::initializer_list<std::string> inputs);

}  // namespace cnccomp
