#pragma once
// HEIDENHAIN conversational programs (Klartext, TNC 320/640/iTNC 530): every motion endpoint in machine coordinates,
// for `cnccomp poses` (same CSV: line,motion,X,Y,Z,A,B,C in mm and degrees). Source: HEIDENHAIN TNC 640 user's manual
// for Klartext programming (ID 1303406): chapters "Programming contours" (L, CC, C, CR, CT, LP, CP) and "Cycles:
// coordinate transformations" (cycle 7 DATUM SHIFT), "Special cycles" (cycle 9 DWELL TIME).
// Read: BEGIN/END PGM (MM, INCH), BLK FORM and TOOL DEF (no motion), TOOL CALL (tool axis = working plane; the tool's
// length from the setup plus DL shifts the tool axis, as G43 does), L with absolute or incremental (IX) words, R0/RL/RR,
// F/FMAX/FAUTO (FMAX = rapid, this block only), M words (M91/M92: machine coordinates, like G53), CC (pole, absolute or
// incremental, none = current position), C with DR+/DR− (DR+ counter-clockwise seen from the + side of the plane
// normal; the plane is given by the two axes of CC [G] for ZX/YZ), CR with R± (+: at most 180°), CT (tangential
// continuation of the previous contour element), LP/CP (polar, PR/PA/IPR/IPA, CP with an incremental tool-axis word for
// a helix), STOP, CYCL DEF 7 (datum shift, absolute or incremental values), CYCL DEF 9 (dwell), other CYCL DEF
// (definitions without motion), ';' comments and '*' structure lines.
// Refused with InputError naming the line: LBL / CALL LBL / CALL PGM (subprograms and repeats), CYCL CALL and M99
// (machining cycles move the axes in ways not evaluated here), Q parameters and FN, PLANE, TRANS, coordinate
// transformation cycles (8, 10, 11, 19, 26, 247), APPR/DEP, RND/CHF, FK, LN, SPL, and anything not listed above.
#include <iosfwd>

#include "postproc/line_reader.hpp"
#include "postproc/poses.hpp"

namespace cnccomp::pp {

/// Reads the Klartext program from `in` and writes the poses CSV (header first): one row per motion block; motion
/// "G0" (FMAX), "G1" (L, LP), "G2"/"G3" (C, CR, CT, CP with DR−/DR+), "G53" (M91/M92) or "-" when an axis position is
/// still unknown. Rotary axes are taken at 0 until programmed, linear axes are unknown until programmed.
/// Throws InputError (options.inputName:line) for malformed or unsupported blocks.
PosesSummary writeKlartextPoses(const AxisLayout& layout, std::istream& in, std::ostream& csv, const PosesOptions& options);
/// The same from a line reader (for `writePoses`, which has looked at the head already).
PosesSummary writeKlartextPoses(const AxisLayout& layout, LineReader& lines, std::ostream& csv, const PosesOptions& options);

}  // namespace cnccomp::pp
