#pragma once
// Sinumerik kinematic chain data (840D sl 4.7+, K12 "transformation definitions with kinematic chains"):
// elements $NK_NAME[e], $NK_NEXT[e], $NK_PARALLEL[e], $NK_TYPE[e] ("OFFSET", "ROT_CONST", "AXIS_LIN",
// "AXIS_ROT"), $NK_AXIS[e], $NK_OFF_DIR[e,0..2], $NK_A_OFF[e], and the transformation record $NT_...[1]
// naming the ends of the tool and part chains. As in real archives, element 0 is the root "ROOT" (a zero OFFSET) and the
// chain is found through the machine data that names it, MD16800 $MN_ROOT_KIN_ELEM_NAME (K7 "Kinematic chain",
// 840D sl function manual special functions 01/2015, 6FC5397-2BP40-5BA2, section 5.2; K12 06/2019 4.2.4: "two kinematic
// subchains, which begin in the respective root element"): $NK_NEXT of the root starts the tool chain, $NK_PARALLEL the
// part (workpiece) chain beside it. The file sets MD16800 itself [G: writing machine data from a program needs the
// access level; enter it by hand if the control refuses]. Every value is absolute, in the NCK's machine coordinates
// (each axis element counts from the axis' machine zero, Link::machineZero).
//
// Meaning used here (and by the apply model) [G: confirm with the K12 manual of the NCK version]:
//   OFFSET     translation by $NK_OFF_DIR (mm)
//   ROT_CONST  rotation about the unit vector $NK_OFF_DIR by $NK_A_OFF (deg)
//   AXIS_LIN   motion along $NK_OFF_DIR by the axis position
//   AXIS_ROT   rotation about $NK_OFF_DIR by (axis position + $NK_A_OFF) (deg)
#include <string>
#include <string_view>
#include <vector>

#include "controllers/common/controller_model.hpp"
#include "controllers/siemens/siemens_plan.hpp"

namespace cnccomp::controllers::siemens {

/// The chain data file (subprogram %_N_CNCCOMP_KINCHAIN_SPF) for the plan; `header` is inserted after the
/// identifier line. Throws ModelError when the chain has more elements than Options::chainMaxElements.
std::string formatKinematicChain(const MachineModel& m, const Plan& plan, const Options& o, const std::string& header);

struct ParsedChain {
    std::vector<common::ChainElement> workpiece, tool;
};

/// Reads a chain data file back as K7/K12 describe it: the root from MD16800, the two subchains from its $NK_NEXT and
/// $NK_PARALLEL to the elements $NT_T_CHAIN_LAST_ELEM / $NT_P_CHAIN_LAST_ELEM name (K12 06/2019 4.2.4.7-8, pp. 285-286);
/// ROT_CONST "rotated through the angle specified in $NK_A_OFF around the direction vector" (K7 01/2015 p.202).
/// InputError (file:line) on syntax errors, unknown variables or element names, missing fields, a broken chain, or
/// axes the machine does not have.
ParsedChain parseKinematicChain(const MachineModel& m, const std::string& path, std::string_view text);

inline constexpr const char* kChainIdentifier = "_N_CNCCOMP_KINCHAIN_SPF";
inline constexpr const char* kRootMachineData = "$MN_ROOT_KIN_ELEM_NAME";  ///< MD16800
inline constexpr const char* kRootName = "ROOT";
inline constexpr const char* kChainFile = "CNCCOMP_KINCHAIN.SPF";

}  // namespace cnccomp::controllers::siemens
