#include "postproc/number_format.hpp"

#include <cmath>
#include <cstdint>
#include <cstdio>

namespace cnccomp::pp {

namespace {
int clampDecimals(const NumberStyle& s) { return s.point ? (s.decimals < 0 ? 0 : (s.decimals > 15 ? 15 : s.decimals)) : 0; }
}  // namespace

double roundToStyle(double value, const NumberStyle& style) {
    const int d = clampDecimals(style);
    const double scaled = std::round(value * kPow10[d]);
    return scaled / kPow10[d];
}

size_t formatNumber(double value, const NumberStyle& style, char* out) {
    const int d = clampDecimals(style);
    if (!std::isfinite(value)) value = 0.0;
    const double scaledAbs = std::round(std::fabs(value) * kPow10[d]);
    size_t n = 0;
    if (scaledAbs >= 9e18) {
        const int len = std::snprintf(out, kMaxNumberChars, "%.*f", d, value);
        return len < 0 ? 0 : static_cast<size_t>(len) < kMaxNumberChars ? static_cast<size_t>(len) : kMaxNumberChars - 1;
    }
    uint64_t scaled = static_cast<uint64_t>(scaledAbs);
    const bool negative = value < 0 && scaled != 0;
    if (negative) out[n++] = '-';
    else if (style.plus) out[n++] = '+';
    uint64_t p10 = 1;
    for (int k = 0; k < d; ++k) p10 *= 10;
    const uint64_t ip = scaled / p10;
    uint64_t frac = scaled % p10;
    char digits[24];
    int fd = d;
    if (style.point && !style.fixed) {
        while (fd > 0 && frac % 10 == 0) {
            frac /= 10;
            --fd;
        }
    }
    const bool omitInteger = style.point && style.bareFraction && ip == 0 && fd > 0;
    if (!omitInteger) {
        int k = 0;
        uint64_t v = ip;
        do {
            digits[k++] = static_cast<char>('0' + v % 10);
            v /= 10;
        } while (v);
        while (k) out[n++] = digits[--k];
    }
    if (style.point) {
        out[n++] = '.';
        for (int k = fd - 1; k >= 0; --k) {
            digits[k] = static_cast<char>('0' + frac % 10);
            frac /= 10;
        }
        for (int k = 0; k < fd; ++k) out[n++] = digits[k];
    }
    return n;
}

double tenTo(int e) {
    static constexpr double kNeg[] = {1, 1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12, 1e-13, 1e-14, 1e-15};
    return e <= 0 && e >= -15 ? kNeg[-e] : std::pow(10.0, e);
}

}  // namespace cnccomp::pp
