#pragma once
// `cnccomp correct` for HEIDENHAIN Klartext programs (BEGIN PGM … END PGM), joint mode and tool-tip (TCP) mode.
//
// Every L endpoint (absolute or incremental words, X Y Z and the machine's rotary letters) is corrected: outside TCP
// mode its machine coordinates (the words + datum shift + the called tool's length on the tool axis) are the nominal
// joints; under M128 / FUNCTION TCPM F TCP|CONT AXIS POS PATHCTRL AXIS the words are the tool tip in the workpiece frame
// and the axis angles, the controller's nominal TCP kinematics (postproc/tcp_model.hpp) give the joints. The erroneous
// machine is solved for the tool tip (the physical tool: --tool-table / --tool-length + DL) and axis, and the words
// written are what the controller turns into exactly those joints. Between endpoints the path check and the splitting
// follow the mode: joints interpolated linearly, or in TCP mode the tip on a straight line in the workpiece frame with
// the angles linear (iTNC 530 user's manual, 12.4 "TCPM FUNCTION", PATHCTRL AXIS).
//
// Conventions (see postproc/klartext_blocks.hpp for the sources):
// - Changed numbers are written in Klartext's signed style (X+12.345), with the program's own decimals (the most
//   any word of that letter had so far, at least 4 in mm and deg, 5 in inch) or --decimals; fixed trailing zeros when
//   the program writes them. Missing axis words are added in X Y Z U V W A B C order.
// - Moves are split where the path would leave the nominal one by more than the tolerance (raised to what the written
//   digits can hold, as for ISO programs): the first piece stays on the original block (its F, M and R words), the
//   others are new blocks "n L … R0|RL|RR ; cnccomp" after it (the comment marks the inserted blocks, for the
//   operator and for `verify`, which finds the test programs' sample blocks again by it). Not split: FMAX moves and blocks with M functions (M129 acts at
//   the end of its block, other M functions at its start or end): their midpoint deviation is reported.
// - Block numbers: the TNC numbers the blocks of a program in ascending order (TNC 620 user's manual for conversational
//   programming 10/2017, 4.2 "Creating and writing programs"). The inserted blocks take the numbers after their
//   original block and every later block's leading number (END PGM's too) moves up by the blocks inserted before it
//   [G: that the control needs the numbers consecutive; only the leading number changes, nothing refers to it].
// - Circles (C, CR, CT, CP) are not kept as circles: a C block cannot hold the other axes' corrections; every circle
//   is replaced by straight L chords meeting the tolerance (CorrectSummary::arcsToLines), and an LP block by an L
//   block with absolute words. Later CT / incremental polar blocks are read from the nominal program (the pole and
//   the tangent of the original contour). CC blocks are kept.
// - M91/M92 blocks are not corrected (like G53: CorrectSummary::notCorrected). What the interpreter does not evaluate
//   (Q parameters, LBL / CALL, CYCL CALL, PLANE, TRANS, FK, APPR/DEP, LN, FUNCTION TCPM with AXIS SPAT or PATHCTRL
//   VECTOR …) is passed through unchanged and reported with its line; what it may change becomes unknown, and --strict
//   counts it. Malformed blocks throw InputError naming the file and line (nothing is written by the CLI).
// - One thread (CorrectOptions::threads is ignored: the output is the same byte for byte).
#include <iosfwd>

#include "postproc/line_reader.hpp"
#include "postproc/correct_program.hpp"

namespace cnccomp::postproc {

/// The comment that ends every block `correct` inserts into a Klartext program.
inline constexpr const char* kKlartextInsertedComment = "; cnccomp";

/// Corrects the Klartext program read by `reader` (its head already looked at) into `out`.
CorrectSummary correctKlartextProgram(const MachineModel& machine, const DeviationSet& deviations, LineReader& reader,
                                      std::ostream& out, const CorrectOptions& options);

}  // namespace cnccomp::postproc
