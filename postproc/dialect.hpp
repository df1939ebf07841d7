#pragma once
// G-code dialects the post-processor reads and writes, and auto-detection from the head of a program.
// Free of Eigen and fmt so that the lexer and its fuzz target build on their own.
#include <optional>
#include <string>
#include <string_view>

namespace cnccomp::postproc {

enum class Dialect {
    Rs274ngc,   ///< RS274NGC / LinuxCNC: ( ) and ; comments, #<name> parameters, o-words, G7/G8 lathe modes
    Fanuc,      ///< Fanuc (and Haas, Mazak EIA): % O1234, #100 macros, G65/M98, G43.4/G43.5, axis integers in increments
    Sinumerik,  ///< Siemens Sinumerik in ISO mode: ; comments, %_N_ headers, NAME(...) calls, R and $ variables
    Printer,    ///< 3D-printer style (Marlin/RepRap): ; comments, E extruder words, M117 text arguments
    Heidenhain, ///< HEIDENHAIN conversational (Klartext): numbered blocks, BEGIN PGM, L/CC/C; read by postproc/klartext_blocks.*
};

/// Where a dialect name is accepted (one name table, postproc/dialect.cpp, serves them all): reading programs
/// (`poses`, the lexer's tests), correcting them (`correct`: also HEIDENHAIN Klartext, which is otherwise detected from
/// BEGIN PGM), or writing test programs (`testprog`, `verify`: LinuxCNC, Fanuc, Sinumerik, HEIDENHAIN; no printer).
enum class DialectUse : unsigned char { Read = 1, Correct = 2, Write = 4 };

/// The dialect a name stands for in `use`, case-insensitive: "rs274ngc" (or "linuxcnc", "rs274", "ngc"), "fanuc" (or
/// "haas"), "sinumerik" (or "siemens"), "printer" (or "marlin", "reprap", "3d-printer"), "heidenhain" (or "klartext",
/// "tnc"), each where that use accepts it; nullopt otherwise.
std::optional<Dialect> parseDialect(std::string_view name, DialectUse use = DialectUse::Read);
/// The name of a dialect as `use` lists it ("rs274ngc" in reading and correcting, "linuxcnc" for test programs).
const char* dialectName(Dialect d, DialectUse use = DialectUse::Read);
/// The names `use` accepts, one per dialect, as an error message lists them: "rs274ngc, fanuc, sinumerik, printer".
std::string dialectNames(DialectUse use);

struct DetectedDialect {
    Dialect dialect = Dialect::Rs274ngc;
    bool certain = false;       ///< false: nothing decisive was found and RS274NGC is the default
    const char* reason = "";    ///< what decided it (a static string)
};

/// Looks at the first bytes of a program: BEGIN PGM → Heidenhain Klartext; ;FLAVOR: / M104 / M109 / E words → printer; %_N_ / TRAORI / CYCLE… →
/// Sinumerik; O-number program header or G65 / M98 / G43.4 → Fanuc; #<name> / o-words → RS274NGC. Numbered
/// variables (#100) exist in both Fanuc and RS274NGC and decide nothing.
/// Ambiguous (clues of two families) or no clue → RS274NGC with certain = false.
DetectedDialect detectDialect(std::string_view head);
/// Line (1-based) of a HEIDENHAIN Klartext "BEGIN PGM" header among the first lines of `head`, 0 when there is none.
int klartextHeaderLine(std::string_view head);

}  // namespace cnccomp::postproc
