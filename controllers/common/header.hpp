#pragma once
// The header comment every controller file carries: controller, machine, deviation set, date, and the
// deviations compensated and NOT compensated (never dropped silently). Each line is wrapped in the caller's
// comment syntax, e.g. prefix "; " for Heidenhain/Sinumerik, "(" + ")" for Fanuc, "# " for INI/HAL.
#include <string>
#include <string_view>
#include <vector>

#include "controllers/backend.hpp"

namespace cnccomp::controllers::common {

struct HeaderInfo {
    std::string controller;            ///< e.g. "LinuxCNC 2.9 (COMP_FILE_TYPE 1, xyzac-trt-kins)"
    std::string machine;               ///< machine name
    std::string machineFile;           ///< machine description file (may be empty; only its file name is printed)
    std::string deviationSource;       ///< deviation set file
    std::string date;                  ///< ISO date
    std::vector<Coverage> compensated;
    std::vector<Coverage> notCompensated;
    std::vector<std::string> notes;    ///< free lines, e.g. "[G] sign convention not confirmed"
};

/// Header info from an emit request and the coverage found so far.
/// The reversal values of the request's set (DeviationSet::reversal, rows B<axis>) that `compensated` does not list,
/// as NOT-compensated entries: these files hold no backlash; the laser route (`cnccomp laser --controller …`, from the
/// ISO 230-2 runs) writes it as backlash β = −B̄ (controllers/common/laser_axis.hpp: Fanuc 1851, Sinumerik MD32450,
/// HEIDENHAIN MP710, ISG bilateral LSEC). makeHeaderInfo adds them to every header; `emit` prints them.
std::vector<Coverage> reversalsNotHeld(const EmitRequest& request, const std::vector<Coverage>& compensated);

HeaderInfo makeHeaderInfo(const EmitRequest& request, std::string_view controller, const EmitResult& coverage,
                          std::vector<std::string> notes = {});

/// The header as text: one line per item, each `prefix + text + suffix` (trailing blanks of an empty text
/// trimmed), lines ended by `eol`. Characters that would end the comment early are replaced inside the text:
/// with suffix ")" (Fanuc) parentheses become brackets; another suffix's first character becomes '_'.
std::string formatHeader(const HeaderInfo& info, std::string_view prefix, std::string_view suffix = "",
                         std::string_view eol = "\n");

/// One header line saying in which frame the file's positions are: the controller's machine coordinates, and the
/// machine-zero of each axis that has one ("X -250 mm, C 90 deg"), or that the description's commands are taken as
/// the controller's machine coordinates (no machine-zero given).
std::string frameNote(const MachineModel& m);

/// The coverage report as printed by `cnccomp emit` (two indented lists).
std::string formatCoverage(const EmitResult& result);

}  // namespace cnccomp::controllers::common
