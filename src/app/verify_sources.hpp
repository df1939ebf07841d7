#pragma once
// What `cnccomp verify --compensation C` points at, loaded as a VerifyCompensation:
//  - a deviation CSV: the ideal compensation of that set;
//  - a folder written by `cnccomp emit`: the backend recognised from the file names (or named), its files read back
//    through Backend::apply, its NOT-compensated list read from the files' header comments;
//  - a folder of test programs corrected by `cnccomp correct`: one file per run, named as `cnccomp testprog` names them
//    (TP<nn>_<run>.<ext>), read back with the post-processor in the dialect of their extension.
#include <optional>
#include <string>
#include <vector>

#include "app/verify.hpp"

namespace cnccomp::app {

struct LoadedCompensation {
    VerifyCompensation compensation;
    std::optional<DeviationSet> identified;  ///< the deviation set itself, when C is a deviation CSV
};

/// `controller`: a backend name to use instead of recognising one ("" = recognise). Throws InputError naming the path
/// when it is neither a deviation CSV, a controller folder nor a folder with every run's corrected program.
LoadedCompensation loadCompensation(const MachineModel& machine, const measurement::MeasurementPlan& plan, const std::string& path,
                                    const std::string& controller = "");

/// The NOT-compensated list of a header comment (controllers/common/header.hpp layout: a line "NOT compensated:" then
/// one indented line per deviation, each in the file's comment syntax); empty when the files carry none.
std::vector<controllers::Coverage> readNotCompensated(const std::vector<controllers::OutputFile>& files);
/// The compensated list of the same header (the line "compensated:"); empty when the files carry none.
std::vector<controllers::Coverage> readCompensated(const std::vector<controllers::OutputFile>& files);

/// The files of a folder (regular files, not recursive), sorted by name.
std::vector<controllers::OutputFile> readFolder(const std::string& dir);

}  // namespace cnccomp::app
