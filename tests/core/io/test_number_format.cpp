// The number formatter's exact mode (NumberStyle::exact) against its oracle, the C library's own printf "%.Nf"
// (glibc: the exact binary value rounded, ties to even, "-0.000" kept), which is also what fmt's "{:.Nf}" writes:
// the volumetric map CSV must read byte for byte as it did when fmt wrote it. The G-code styles are tested in
// test_postproc_lexer.cpp.
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

}  // namespace
}  // namespace cnccomp
