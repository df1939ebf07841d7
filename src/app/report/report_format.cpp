#include "app/report/report_format.hpp"

#include <cmath>

#include <fmt/format.h>

namespace cnccomp::app::report {

double niceNumber(double x) {
    if (!(x > 0) || !std::isfinite(x)) return 1.0;
    const double p = std::pow(10.0, std::floor(std::log10(x)));
    for (double m : {1.0, 2.0, 2.5, 5.0, 10.0})
        if (m * p >= x * (1 - 1e-12)) return m * p;
    return 10 * p;
}

std::string fixed(double v, int decimals) {
    if (!std::isfinite(v)) return "–";
    if (std::abs(v) < 0.5 * std::pow(10.0, -decimals)) v = 0.0;  // no "-0.00"
    return fmt::format("{:.{}f}", v, decimals);
}

}  // namespace cnccomp::app::report
