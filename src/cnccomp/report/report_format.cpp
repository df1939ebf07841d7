#include "cnccomp/report/report_format.hpp"

#include <cmath>

#include <fmt/format.h>

namespace cnccomp::report {

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

std::string jsonString(std::string_view s) {
    std::string o = "\"";
    for (size_t i = 0; i < s.size(); ++i) {
        const char c = s[i];
        switch (c) {
            case '"': o += "\\\""; break;
            case '\\': o += "\\\\"; break;
            case '\n': o += "\\n"; break;
            case '\r': o += "\\r"; break;
            case '\t': o += "\\t"; break;
            case '/': o += i > 0 && s[i - 1] == '<' ? "\\/" : "/"; break;
            default:
                if (static_cast<unsigned char>(c) < 0x20) o += fmt::format("\\u{:04x}", static_cast<unsigned>(c));
                else o += c;
        }
    }
    return o + "\"";
}

std::string jsonNumber(double v) {
    if (!std::isfinite(v)) return "null";
    if (v == 0) return "0";
    return fmt::format("{:.9g}", v);
}

}  // namespace cnccomp::report
