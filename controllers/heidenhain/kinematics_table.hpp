#pragma once
// HEIDENHAIN iTNC 530 kinematics description with KinematicsComp (iTNC 530 HSCI technical manual 07/2013,
// "KinematicsComp"; the TNC 640 / TNC7 describe kinematics in the machine configuration instead: not this route).
// Values are absolute, in the TNC's machine coordinates (an axis whose machine datum differs from the description's
// zero gets a Trans row of its machine-zero next to its MachAxis; AXISPOS are machine positions):
// the transformation chain starts at the tool reference point, walks up the tool side to MachBase and on to
// the table. Rows: KEY Trans (AXIS X/Y/Z: shift, mm; AXIS A/B/C: rotation about X/Y/Z, deg), MachAxis (an axis
// moves here), MachBase, ToolAxis. Location errors (ISO 230-1 X0C ...) are Trans rows next to the MachAxis of
// their axis; component errors (EXX ... ECC) are Trans rows whose COMPTAB names a column of a .COM table
// (AXISPOS + C1..C6 = error in x y z a b c) and that sit right beside their MachAxis row.
//
// Meaning used by cnccomp's writer and apply model [G: confirm signs with the machine's KinematicsDesign]:
// the rows form a plain product of transforms from the tool reference point to the table; MachAxis rows before
// MachBase are walked from the tool to the base (their motion enters inverted), rows after MachBase from the
// base to the table; a COMPTAB row's value is its COORD plus the interpolated table value, so the tool-side
// .COM columns hold the negated ISO errors (the inverse transform) and the table-side columns the ISO errors.
#include <string>
#include <string_view>
#include <vector>

#include "cnccomp/deviations.hpp"
#include "controllers/backend.hpp"
#include "controllers/common/controller_model.hpp"

namespace cnccomp::controllers::heidenhain {

struct Options {
    int maxTransformRows = 50;  ///< Trans + MachAxis rows of one description [V]
    int maxCompRows = 256;      ///< rows per .COM table [V for older TNC]
    int maxCompEntries = 100;   ///< COMPTAB entries, the MachAxis rows included (iTNC 530 manual p.686) [V]
};

/// The files: the kinematics description (<MACHINE>.TAB) and one .COM table per axis with component errors.
/// Throws ModelError when the machine's axes cannot be described (axis name without a TNC direction, direction
/// not along that name) or a limit is exceeded.
EmitResult emitFiles(const EmitRequest& request, const Options& options);

struct ParsedKinematics {
    std::vector<common::ChainElement> workpiece, tool;
    std::vector<common::ComponentTable> tables;
};

/// Reads the files back (InputError file:line): keys and their order as the iTNC 530 HSCI technical manual 07/2013
/// lists them (p.671), .COM columns AXISPOS, C1..C6 (p.680); the tool-side walk and the sign of its tables are [G].
ParsedKinematics parseFiles(const MachineModel& m, const std::vector<OutputFile>& files);

/// Unit direction of a TNC axis letter: X/U/A → x, Y/V/B → y, Z/W/C → z; or zero for other names.
Vec3 letterDirection(std::string_view axis);

}  // namespace cnccomp::controllers::heidenhain
