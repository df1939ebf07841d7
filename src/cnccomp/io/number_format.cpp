#include "cnccomp/io/number_format.hpp"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>

namespace cnccomp::io {

namespace {
int clampDecimals(const NumberStyle& s) { return s.point ? (s.decimals < 0 ? 0 : (s.decimals > 15 ? 15 : s.decimals)) : 0; }

size_t viaPrintf(double value, int decimals, char* out) {
    const int len = std::snprintf(out, kMaxNumberChars, "%.*f", decimals, value);
    return len < 0 ? 0 : static_cast<size_t>(len) < kMaxNumberChars ? static_cast<size_t>(len) : kMaxNumberChars - 1;
}

/// "00" … "99": two digits per division.
constexpr char kPairs[] =
    "0001020304050607080910111213141516171819202122232425262728293031323334353637383940414243444546474849"
    "5051525354555657585960616263646566676869707172737475767778798081828384858687888990919293949596979899";

/// `scaled` / 10^d written with d decimals (at least one integer digit; no point when d = 0) at `out`; returns the
/// length.
size_t writeFixed(uint64_t scaled, int d, char* out) {
    char buf[24];
    char* const end = buf + sizeof buf;
    char* p = end;
    while (scaled >= 100) {
        const unsigned r = static_cast<unsigned>(scaled % 100);
        scaled /= 100;
        p -= 2;
        std::memcpy(p, kPairs + 2 * r, 2);
    }
    if (scaled >= 10) {
        p -= 2;
        std::memcpy(p, kPairs + 2 * scaled, 2);
    } else {
        *--p = static_cast<char>('0' + scaled);
    }
    while (end - p < d + 1) *--p = '0';
    const size_t whole = static_cast<size_t>(end - p - d);
    std::memcpy(out, p, whole);
    if (d == 0) return whole;
    out[whole] = '.';
    std::memcpy(out + whole + 1, p + whole, static_cast<size_t>(d));
    return whole + 1 + static_cast<size_t>(d);
}

/// 10^0 … 10^15 as integers.
constexpr uint64_t kPow10u[] = {1ull, 10ull, 100ull, 1000ull, 10000ull, 100000ull, 1000000ull, 10000000ull,
                                100000000ull, 1000000000ull, 10000000000ull, 100000000000ull, 1000000000000ull,
                                10000000000000ull, 100000000000000ull, 1000000000000000ull};

/// Exactly `d` digits of v (< 10^d, d ≤ 9) at `out`, two per division by a constant on 32 bits.
inline void writeDigits32(uint32_t v, int d, char* out) {
    char* p = out + d;
    for (; d >= 2; d -= 2) {
        const uint32_t r = v % 100;
        v /= 100;
        p -= 2;
        std::memcpy(p, kPairs + 2 * r, 2);
    }
    if (d) *--p = static_cast<char>('0' + v);
}

/// v's decimal digits (no leading zeros, "0" for 0) at `out`; returns the length.
inline size_t writeUnsigned32(uint32_t v, char* out) {
    const int n = v < 10 ? 1 : v < 100 ? 2 : v < 1000 ? 3 : v < 10000 ? 4 : v < 100000 ? 5 : v < 1000000 ? 6
                : v < 10000000 ? 7 : v < 100000000 ? 8 : v < 1000000000 ? 9 : 10;
    if (n == 10) {
        writeDigits32(v % 1000000000u, 9, out + 1);
        out[0] = static_cast<char>('0' + v / 1000000000u);
    } else {
        writeDigits32(v, n, out);
    }
    return static_cast<size_t>(n);
}

/// NumberStyle::exact. The product p = |value| · 10^d is computed with one rounding (10^d is exact), so it is within
/// p · 2^-53 of the exact product; unless p is that close to a half-integer, rounding p to the nearest integer rounds
/// the exact product too, which is printf's result. The rare undecided cases (and non-finite or huge values) go to
/// snprintf itself.
/// The digits: with up to 9 decimals and an integer part below 2^32 (every number a map or a program holds), the
/// integer part is |value| truncated (exact) and the fraction the rounded product less it times 10^d, at most one
/// carry: rounding is monotone, so p ≥ ⌊|value|⌋ · 10^d. Both are written on 32 bits, two digits per step, without the
/// 64-bit divisions of the general path (about twice as fast: BM_MapCsvRowsFormat).
size_t formatExact(double value, int d, char* out) {
    const double a = std::fabs(value);
    const double p = a * kPow10[d];
    if (!(p < 4e15)) return viaPrintf(value, d, out);  // also NaN and infinities
    const uint64_t whole = static_cast<uint64_t>(p);      // p < 2^52: truncation is floor, and exact
    const double frac = p - static_cast<double>(whole);  // exact
    if (std::fabs(frac - 0.5) <= p * 0x1p-52) return viaPrintf(value, d, out);
    const uint64_t scaled = whole + (frac > 0.5 ? 1 : 0);
    size_t n = 0;
    if (std::signbit(value)) out[n++] = '-';
    if (d <= 9 && a < 4294967295.0) {
        uint64_t integer = static_cast<uint64_t>(a);
        uint64_t fraction = scaled - integer * kPow10u[d];
        if (fraction >= kPow10u[d]) fraction -= kPow10u[d], ++integer;
        if (integer <= 0xffffffffull) {
            n += writeUnsigned32(static_cast<uint32_t>(integer), out + n);
            if (d == 0) return n;
            out[n++] = '.';
            writeDigits32(static_cast<uint32_t>(fraction), d, out + n);
            return n + static_cast<size_t>(d);
        }
    }
    return n + writeFixed(scaled, d, out + n);
}
/// std::round (half away from zero), inline: x86-64's baseline has no rounding instruction and the library call costs
/// more than the number's other arithmetic. For |x| < 2^52 the truncation t is exact, so is x − t (the fraction of
/// x) and t ± 1; the sign is x's, −0 included. Larger values are integers already (NaN and infinities pass).
inline double roundHalfAway(double x) {
    if (!(std::fabs(x) < 0x1p52)) return x;
    const double t = static_cast<double>(static_cast<int64_t>(x));
    return std::copysign(std::fabs(x - t) >= 0.5 ? t + std::copysign(1.0, x) : t, x);
}

}  // namespace

double roundToStyle(double value, const NumberStyle& style) {
    const int d = clampDecimals(style);
    const double scaled = roundHalfAway(value * kPow10[d]);
    return scaled / kPow10[d];
}

size_t formatNumber(double value, const NumberStyle& style, char* out) {
    const int d = clampDecimals(style);
    if (style.exact && style.point && style.fixed && !style.plus && !style.bareFraction) return formatExact(value, d, out);
    if (!std::isfinite(value)) value = 0.0;
    const double a = std::fabs(value);
    const double scaledAbs = roundHalfAway(a * kPow10[d]);
    size_t n = 0;
    if (scaledAbs >= 9e18) return viaPrintf(value, d, out);
    uint64_t scaled = static_cast<uint64_t>(scaledAbs);
    const bool negative = value < 0 && scaled != 0;
    if (negative) out[n++] = '-';
    else if (style.plus) out[n++] = '+';
    const uint64_t p10 = kPow10u[d];
    // ip = scaled / 10^d and frac = scaled % 10^d without a 64-bit division by a variable: below 2^52 the integer part
    // of a is exact and ⌊a⌋ · 10^d ≤ scaled ≤ (⌊a⌋ + 1) · 10^d (rounding is monotone, both bounds representable), so
    // the quotient is ⌊a⌋ or one more.
    uint64_t ip, frac;
    if (scaledAbs < 0x1p52) {
        ip = static_cast<uint64_t>(a);
        frac = scaled - ip * p10;
        if (frac >= p10) frac -= p10, ++ip;
    } else {
        ip = scaled / p10;
        frac = scaled % p10;
    }
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

}  // namespace cnccomp::io
