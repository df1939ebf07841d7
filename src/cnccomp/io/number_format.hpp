#pragma once
// Writing decimal numbers fast, without a format string: the one number formatter of the project's hot output loops.
//  - G-code in a program's own style (postproc): fixed decimals or trimmed trailing zeros, with or without the leading
//    zero (".5"), an explicit '+', or Fanuc-style integers in least input increments.
//  - Data files that must read exactly as printf's / fmt's "%.Nf" (`exact`: the volumetric map CSV), several times
//    faster than either for the numbers a machine produces.
#include <cstddef>

namespace cnccomp::io {

struct NumberStyle {
    int decimals = 4;           ///< digits after the point
    bool fixed = true;          ///< keep trailing zeros ("1.500"); false trims them ("1.5", "1.")
    bool bareFraction = false;  ///< ".5" instead of "0.5"
    bool plus = false;          ///< "+1.5" for positive values
    bool point = true;          ///< false: an integer without a point (Fanuc increments; decimals ignored)
    /// The text of printf's "%.Nf" byte for byte (C11 7.21.6.1: the exact binary value rounded to N decimals; glibc
    /// and fmt round an exact tie to even and keep the sign of a negative value that rounds to zero: "-0.000"; "nan",
    /// "inf"). Only with fixed, point, no '+', no bare fraction. Off: G-code's style (value · 10^N rounded half away
    /// from zero, never "-0", a non-finite value written as 0).
    bool exact = false;
};

inline constexpr size_t kMaxNumberChars = 48;

/// 10^0 … 10^22: the powers of ten a double holds exactly (reading and writing decimal digits).
inline constexpr double kPow10[] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
                                    1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

/// 10^e for the decimals of a written number (e in −15 … 0 from a table; beyond: std::pow).
double tenTo(int e);

/// Writes `value` into `out` (at least kMaxNumberChars bytes) and returns the length. Never writes "-0" (but see
/// NumberStyle::exact). Values too large for the style (|value| · 10^decimals ≥ 9e18) are written by snprintf, cut
/// at kMaxNumberChars − 1 characters.
size_t formatNumber(double value, const NumberStyle& style, char* out);

/// `value` rounded to the style's resolution (what a controller reads back from formatNumber's text).
double roundToStyle(double value, const NumberStyle& style);

}  // namespace cnccomp::io
