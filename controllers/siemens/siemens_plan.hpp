#pragma once
// Which Sinumerik 840D sl function takes which deviation, and with which numbers.
//
// - Kinematic chain ($NK_ elements, used by TRAORI): the location of every rotary axis and of the tool spindle
//   (ISO 230-7 location errors: offsets and orientations), with the linear axes written orthogonal.
// - CEC tables (K3 "sag / cross-axis compensation"): squareness of the linear axes as straight lines
//   (output = slope x input), straightness (cross-axis) component errors of linear axes, radial/axial component
//   errors of a rotary axis no other rotary axis carries.
// - EEC tables (K3 "leadscrew / encoder error compensation"): positioning component errors of each axis.
//
// Squareness rotates a slide's frame, and with it whatever the slide carries. The CEC trims straighten the
// slide motions; the rotation the slides give the head/spindle/table is folded into the first kinematic-chain
// element after the last linear axis, so TRAORI sees the real orientation (exact, not small-angle).
#include <string>
#include <vector>

#include "cnccomp/deviations.hpp"
#include "controllers/backend.hpp"
#include "controllers/common/axis_table.hpp"

namespace cnccomp::controllers::siemens {

struct Options {
    int tablePoints = 201;      ///< points per CEC/EEC table the writer aims at
    int cecMaxPoints = 2000;    ///< MD18342 $MN_MM_CEC_MAX_POINTS (upper limit of the machine data) [G]
    int cecMaxTables = 62;      ///< number of CEC tables the NCK holds [G]
    int eecMaxPoints = 5000;    ///< MD38000 $MA_MM_ENC_COMP_MAX_POINTS [G]
    int chainMaxElements = 64;  ///< kinematic chain elements [G]
};

/// CEC table: output axis command += value(input axis position). Values mm (linear output) or deg.
struct CecTable {
    int input = -1, output = -1;  ///< machine axis indices
    common::EquidistantTable table;       ///< positions in mm / deg of the input axis
    std::vector<std::string> sources;
};

/// EEC table: the axis' positioning error (mm / deg) at its position; the NCK moves the axis by -value.
struct EecTable {
    int axis = -1;
    common::EquidistantTable table;
    std::vector<std::string> sources;
};

struct Plan {
    /// Per side (0 workpiece, 1 tool) and link: nominal placement · the location error the chain takes.
    std::vector<Pose> placed[2];
    /// Per side: rotation folded after the last link when no link follows the last linear axis.
    Pose end[2] = {Pose::Identity(), Pose::Identity()};
    std::vector<CecTable> cec;
    std::vector<EecTable> eec;
    std::vector<Coverage> compensated, notCompensated;
};

inline int sideIndex(Side s) { return s == Side::Tool ? 1 : 0; }

/// Throws ModelError when the machine's structure or a controller limit does not allow the compensation.
Plan makePlan(const MachineModel& m, const DeviationSet& d, const Options& o);

/// Machine axis name as the files write it: AX<n> in controller order (X Y Z ... A B C).
std::string axisName(const MachineModel& m, int machineAxis);

}  // namespace cnccomp::controllers::siemens
