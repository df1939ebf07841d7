#pragma once
// G-code dialects the post-processor reads and writes, and auto-detection from the head of a program.
// Free of Eigen and fmt so that the lexer and its fuzz target build on their own.
#include <optional>
#include <string_view>

namespace cnccomp::pp {

enum class Dialect {
    Rs274ngc,   ///< RS274NGC / LinuxCNC: ( ) and ; comments, #<name> parameters, o-words, G7/G8 lathe modes
    Fanuc,      ///< Fanuc (and Haas, Mazak EIA): % O1234, #100 macros, G65/M98, G43.4/G43.5, axis integers in increments
    Sinumerik,  ///< Siemens Sinumerik in ISO mode: ; comments, %_N_ headers, NAME(...) calls, R and $ variables
    Printer,    ///< 3D-printer style (Marlin/RepRap): ; comments, E extruder words, M117 text arguments
    Heidenhain, ///< HEIDENHAIN conversational (Klartext): numbered blocks, BEGIN PGM, L/CC/C; read by postproc/klartext_blocks.*
};

/// "rs274ngc" (or "linuxcnc"), "fanuc", "sinumerik", "printer" (or "marlin", "reprap"); nullopt otherwise.
/// (Heidenhain is detected from BEGIN PGM, not named here; `correct --dialect heidenhain` names it.)
std::optional<Dialect> parseDialect(std::string_view name);
const char* dialectName(Dialect d);

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

}  // namespace cnccomp::pp
