#pragma once
// Small text helpers of the report: round scale steps, numbers with "–" for unknown values, JSON literals.
#include <string>
#include <string_view>

#include "cnccomp/io/markup.hpp"

namespace cnccomp::app::report {

/// The smallest of 1, 2, 2.5, 5 × 10^k that is ≥ x (x > 0; 1 otherwise).
double niceNumber(double x);
/// `v` with `decimals` decimals; "–" when not finite.
std::string fixed(double v, int decimals);
using cnccomp::io::jsonString;  // io/markup.hpp

}  // namespace cnccomp::app::report
