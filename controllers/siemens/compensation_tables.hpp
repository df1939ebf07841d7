#pragma once
// CEC and EEC table files of the Sinumerik 840D sl (K3 compensation function manual).
//
// CEC (%_N_NC_CEC_INI): per table t, points $AN_CEC[t,0..N-1], $AN_CEC_INPUT_AXIS[t]=(AXj),
// $AN_CEC_OUTPUT_AXIS[t]=(AXk), $AN_CEC_STEP/_MIN/_MAX[t] with N = (MAX-MIN)/STEP + 1 (must fit
// MD18342 MM_CEC_MAX_POINTS), $AN_CEC_DIRECTION[t]=0 (both directions), $AN_CEC_MULT_BY_TABLE[t]=0,
// $AN_CEC_IS_MODULO[t]. The interpolated value is added to the output axis [G: sign as written here, the
// value is the correction to add]. Beyond MIN/MAX the end value holds; a modulo table wraps.
//
// EEC (%_N_AX_EEC_INI): $AA_ENC_COMP[0,n,AXj], $AA_ENC_COMP_STEP/_MIN/_MAX/_IS_MODULO[0,AXj]; the value is
// the axis' positioning error: "a positive value moves the axis in the negative direction" (K3).
#include <string>
#include <string_view>
#include <vector>

#include "controllers/siemens/siemens_plan.hpp"

namespace cnccomp::controllers::siemens {

inline constexpr const char* kCecIdentifier = "_N_NC_CEC_INI";
inline constexpr const char* kCecFile = "NC_CEC.INI";
inline constexpr const char* kEecIdentifier = "_N_AX_EEC_INI";
inline constexpr const char* kEecFile = "AX_EEC.INI";

std::string formatCec(const MachineModel& m, const std::vector<CecTable>& tables, const std::string& header);
std::string formatEec(const MachineModel& m, const std::vector<EecTable>& tables, const std::string& header);

/// Readers: InputError (file:line) on syntax errors, unknown variables, inconsistent MIN/MAX/STEP and point
/// count, gaps in the points, modulo tables that do not close on themselves, unknown axes.
std::vector<CecTable> parseCec(const MachineModel& m, const std::string& path, std::string_view text);
std::vector<EecTable> parseEec(const MachineModel& m, const std::string& path, std::string_view text);

}  // namespace cnccomp::controllers::siemens
