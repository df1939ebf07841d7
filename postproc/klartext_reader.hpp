#pragma once
// HEIDENHAIN conversational programs (Klartext, TNC 320/640/iTNC 530): every motion endpoint in machine coordinates,
// for `cnccomp poses` (same CSV: line,motion,X,Y,Z,A,B,C in mm and degrees). Source: HEIDENHAIN TNC 640 user's manual
// for Klartext programming (ID 1303406): chapters "Programming contours" (L, CC, C, CR, CT, LP, CP) and "Cycles:
// coordinate transformations" (cycle 7 DATUM SHIFT), "Special cycles" (cycle 9 DWELL TIME).
// The blocks are read by the interpreter shared with `cnccomp correct` (postproc/klartext_blocks.hpp, which lists what
// is read); what it does not evaluate (LBL / CALL LBL / CALL PGM, CYCL CALL, M99, Q parameters and FN, PLANE, TRANS,
// transformation cycles, APPR/DEP, RND/CHF, FK, LN, SPL, FUNCTION TCPM with AXIS SPAT or PATHCTRL VECTOR …) is refused
// here with InputError naming the line. Moves in tool-tip mode (M128, FUNCTION TCPM) are labelled "G1 TCP" …: their
// X Y Z are the programmed tool tip (workpiece frame), not machine coordinates.
#include <iosfwd>

#include "postproc/line_reader.hpp"
#include "postproc/poses.hpp"

namespace cnccomp::postproc {

/// Reads the Klartext program from `in` and writes the poses CSV (header first): one row per motion block; motion
/// "G0" (FMAX), "G1" (L, LP), "G2"/"G3" (C, CR, CT, CP with DR−/DR+), "G53" (M91/M92) or "-" when an axis position is
/// still unknown. Rotary axes are taken at 0 until programmed, linear axes are unknown until programmed.
/// Throws InputError (options.inputName:line) for malformed or unsupported blocks.
PosesSummary writeKlartextPoses(const AxisLayout& layout, std::istream& in, std::ostream& csv, const PosesOptions& options);
/// The same from a line reader (for `writePoses`, which has looked at the head already).
PosesSummary writeKlartextPoses(const AxisLayout& layout, LineReader& lines, std::ostream& csv, const PosesOptions& options);

}  // namespace cnccomp::postproc
