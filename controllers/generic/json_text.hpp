#pragma once
// JSON text of the generic backend's own files (deviation set, grid map). They are read back with cnccomp's one JSON
// reader, io/json.hpp.
#include <string>
#include <string_view>
#include <vector>

namespace cnccomp::controllers::generic {

/// JSON text of a string (quoted, escaped).
std::string jsonString(std::string_view s);
/// Shortest round-trip text of a finite number ("0" for either zero); ModelError for a number that is not finite.
std::string jsonNumber(double v);
/// "[a, b, …]" of numbers.
std::string jsonNumbers(const std::vector<double>& v);

}  // namespace cnccomp::controllers::generic
