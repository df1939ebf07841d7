// The number formatter's exact mode (NumberStyle::exact) against its oracle, the C library's own printf "%.Nf"
// (glibc: the exact binary value rounded, ties to even, "-0.000" kept), which is also what fmt's "{:.Nf}" writes:
// the volumetric map CSV must read byte for byte as it did when fmt wrote it. The G-code styles: against their
// definition written out here, and in test_postproc_lexer.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>

#include <fmt/format.h>

#include "cnccomp/io/number_format.hpp"

namespace cnccomp {
using namespace cnccomp::io;
namespace {

std::string exact(double v, int decimals) {
    NumberStyle s;
    s.decimals = decimals;
    s.exact = true;
    char buf[kMaxNumberChars];
    return std::string(buf, formatNumber(v, s, buf));
}

std::string viaPrintf(double v, int decimals) {
    char buf[kMaxNumberChars];
    std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
    return buf;
}

TEST(NumberFormat, ExactIsPrintfOnEdgeCases) {
    const double cases[] = {0.0, -0.0, 0.5, 1.5, 2.5, -2.5, 0.25, 0.125, 0.0078125, -1e-9, 1e-9, 1e-300, -1e-300,
                            0.0000005, 0.0000015, -0.0000005, 123.4565, 9.9999995, 999999.9999995, 4e9, 1e15, 4e15,
                            -4e15, 1e20, -1e20, 123456789012.345678,
                            std::numeric_limits<double>::quiet_NaN(), -std::numeric_limits<double>::quiet_NaN(),
                            std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
                            std::numeric_limits<double>::denorm_min(), std::numeric_limits<double>::max()};
    for (int d = 0; d <= 15; ++d)
        for (double v : cases) {
            const std::string want = viaPrintf(v, d);
            if (want.size() + 1 >= kMaxNumberChars) continue;  // beyond the buffer (max double): cut, as documented
            EXPECT_EQ(exact(v, d), want) << v << " with " << d << " decimals";
        }
    EXPECT_EQ(exact(-1e-9, 6), "-0.000000");  // the sign of a negative value that rounds to zero is kept
    EXPECT_EQ(exact(0.0078125, 6), "0.007812");  // an exact tie goes to even
    EXPECT_EQ(exact(0.0234375, 6), "0.023438");
    EXPECT_EQ(exact(12.0, 0), "12");            // no point without decimals
}

TEST(NumberFormat, ExactIsPrintfAndFmtOnRandomValues) {
    std::mt19937_64 rng(19);
    std::uniform_real_distribution<double> u(-1, 1);
    for (int d = 0; d <= 12; ++d)
        for (int i = 0; i < 20000; ++i) {
            const double v = u(rng) * std::pow(10.0, static_cast<int>(rng() % 16) - 8);
            ASSERT_EQ(exact(v, d), viaPrintf(v, d)) << v << " with " << d << " decimals";
            // Binary fractions near ties: multiples of 2^-k, half a unit of the last decimal off or on a tie.
            const double t = static_cast<double>(static_cast<long>(rng() % 2000001) - 1000000) / std::ldexp(1.0, static_cast<int>(rng() % 24));
            ASSERT_EQ(exact(t, d), viaPrintf(t, d)) << t << " with " << d << " decimals";
        }
    for (int i = 0; i < 20000; ++i) {  // the map CSV's styles, against fmt as it wrote them
        const double v = u(rng) * 500;
        ASSERT_EQ(exact(v, 6), fmt::format("{:.6f}", v));
        ASSERT_EQ(exact(v * 1e-3, 5), fmt::format("{:.5f}", v * 1e-3));
    }
}

/// G-code's style, written from its definition (NumberStyle::exact's comment: value · 10^N rounded half away from zero
/// by the C library's round, never "-0", digits by 64-bit division; oracle: an independent transcription, the
/// formatter's own before it lost its division).
std::string gcodeReference(double v, const NumberStyle& s) {
    const int d = s.point ? s.decimals : 0;
    uint64_t p10 = 1;
    for (int k = 0; k < d; ++k) p10 *= 10;
    const auto scaled = static_cast<uint64_t>(std::round(std::fabs(v) * static_cast<double>(p10)));
    uint64_t ip = scaled / p10, frac = scaled % p10;
    int fd = d;
    if (s.point && !s.fixed)
        while (fd > 0 && frac % 10 == 0) frac /= 10, --fd;
    std::string out = v < 0 && scaled != 0 ? "-" : s.plus ? "+" : "";
    if (!(s.point && s.bareFraction && ip == 0 && fd > 0)) out += std::to_string(ip);
    if (s.point) out += "." + (fd > 0 ? fmt::format("{:0{}d}", frac, fd) : std::string());
    return out;
}

TEST(NumberFormat, GcodeStyleIsValueTimesTenToTheNRoundedHalfAwayFromZero) {
    std::mt19937_64 rng(23);
    std::uniform_real_distribution<double> u(-1, 1);
    NumberStyle styles[4];
    styles[1].fixed = false;
    styles[2].fixed = false, styles[2].bareFraction = true, styles[2].plus = true;
    styles[3].point = false;
    int checked = 0;
    for (NumberStyle s : styles)
        for (int d = 0; d <= 9; ++d) {
            s.decimals = d;
            char buf[kMaxNumberChars];
            const double p = std::pow(10.0, s.point ? d : 0);  // no point: an integer, decimals ignored
            const double ties[] = {0.5 / p, -0.5 / p, 1.5 / p, 2.5 / p, -2.5 / p, 0.49999999999999994 / p, 9.9999995,
                                   -9.9999995, 999999.5 / p, 1e-300, -1e-300, 0.0, -0.0, 4503599627370495.5 / p,
                                   4503599627370497.0 / p, 1e15 / p, -1e15 / p, 123456789.987654321};
            for (double v : ties) {
                EXPECT_EQ(std::string(buf, formatNumber(v, s, buf)), gcodeReference(v, s)) << v << " with " << d << " decimals";
                EXPECT_EQ(roundToStyle(v, s), std::round(v * p) / p) << v << " with " << d << " decimals";
                ++checked;
            }
            for (int i = 0; i < 5000; ++i) {
                const double v = u(rng) * std::pow(10.0, static_cast<int>(rng() % 14) - 6);
                const double t = static_cast<double>(static_cast<long>(rng() % 2000001) - 1000000) / std::ldexp(1.0, static_cast<int>(rng() % 24));
                for (double x : {v, t}) {
                    ASSERT_EQ(std::string(buf, formatNumber(x, s, buf)), gcodeReference(x, s)) << x << " with " << d << " decimals";
                    ASSERT_EQ(roundToStyle(x, s), std::round(x * p) / p) << x << " with " << d << " decimals";
                    ++checked;
                }
            }
        }
    EXPECT_EQ(checked, 4 * 10 * (18 + 10000));
}

}  // namespace
}  // namespace cnccomp
