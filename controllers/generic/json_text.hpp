#pragma once
// JSON numbers of the generic backend's own files (deviation set, grid map); strings are escaped by io/markup.hpp's
// jsonString. The files are read back with cnccomp's one JSON reader, io/json.hpp.
#include <string>
#include <vector>

namespace cnccomp::controllers::generic {

/// Shortest round-trip text of a finite number ("0" for either zero); ModelError for a number that is not finite.
std::string jsonNumber(double v);
/// "[a, b, …]" of numbers.
std::string jsonNumbers(const std::vector<double>& v);

}  // namespace cnccomp::controllers::generic
