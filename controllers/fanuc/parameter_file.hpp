#pragma once
// Fanuc Series 30i parameter file (parameter manual B-63950EN, "inputting and outputting parameters"):
//
//   (comment lines before the first % are ignored by the control: cnccomp's header goes there)
//   %
//   N19680Q1L1P21                 path-type parameter: number, Q1, path L1, value P
//   N01220Q1A1P-0.0150A2P0.0100   axis-type parameter: A<axis number>P<value> for each axis
//   N10012Q0P-3                   pitch error compensation data: N(10000 + point number), Q0, value
//   %
//
// Every line between the two % lines must match  N<5 digits>Q<0|1>(P<v>|L<n>P<v>|(A<n>P<v>)+)  with
// <v> = [+-]digits[.digits] (no exponent). Blocks end with LF. [G: the L path word and the Q0 marker of the
// pitch data follow the 30i output format as far as public manuals show it; confirm on the control.]
#include <map>
#include <string>
#include <string_view>
#include <vector>

namespace cnccomp::controllers::fanuc {

struct Parameter {
    int number = 0;
    int q = 1;                 ///< 1 parameter, 0 pitch error compensation data
    char kind = 'P';           ///< 'P' plain, 'L' path type, 'A' axis type
    std::map<int, std::string> values;  ///< by path / axis number (0 for plain); raw text
    int line = 0;
};

struct ParameterFile {
    std::string path;
    std::vector<Parameter> parameters;
    int closingLine = 0;  ///< line of the closing %: where a missing parameter was expected
    /// Parameter by (number, q), or nullptr.
    const Parameter* find(int number, int q = 1) const;
};

/// One line of the grammar above.
std::string formatParameter(const Parameter& p);
/// Whole file: header (comment lines) + "%" + lines + "%".
std::string formatParameterFile(const std::string& header, const std::vector<Parameter>& parameters);

/// InputError(path, line, ...) on any line between the % lines that does not match the grammar, on a missing
/// %, on text after the closing %, on non-comment text before the opening %, and on a parameter given twice.
ParameterFile parseParameterFile(const std::string& path, std::string_view text);

/// Value of parameter `number` for index `index` (path or axis number; 0 for plain) as a number, or
/// `fallback` when absent; InputError when present but not a number.
double value(const ParameterFile& f, int number, int index, double fallback, int q = 1);
/// Same, but InputError (naming the parameter) when absent.
double required(const ParameterFile& f, int number, int index, int q = 1);

/// Fixed-point text for P values (no exponent, no negative zero).
std::string decimal(double v, int decimals);

}  // namespace cnccomp::controllers::fanuc
