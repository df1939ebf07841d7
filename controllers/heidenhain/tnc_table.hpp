#pragma once
// HEIDENHAIN TNC table files (.TAB kinematics descriptions, .COM KinematicsComp tables):
//
//   BEGIN NAME.TAB MM          first line: BEGIN, file name, unit
//   NR   KEY     AXIS  COORD   header line: column names; each column starts where its name starts
//   0    Trans   X     0.016   rows, cells in the columns fixed by the header
//   [END]                      last line of the table
//
// The TNC stops reading at [END]; cnccomp puts its comment block (header comment: machine, deviation set,
// date, compensated, NOT compensated) after it, each line starting with ';'.
#include <string>
#include <string_view>
#include <vector>

namespace cnccomp::controllers::heidenhain {

struct TncTable {
    std::string name;                               ///< e.g. "MULTITASKING.TAB"
    std::vector<std::string> columns;               ///< e.g. NR KEY AXIS COORD FILE DOC COMPTAB
    std::vector<std::vector<std::string>> rows;     ///< cells per column (NR included)
    std::vector<int> lines;                         ///< source line of each row (reader)
    std::string path;                               ///< reader: file name for messages

    int column(const std::string& name) const;      ///< index or -1
    /// Cell text (trimmed), empty when the column does not exist.
    const std::string& cell(size_t row, int column) const;
};

/// Fixed-width text; `comment` lines are appended after [END] (each must start with ';').
std::string formatTncTable(const TncTable& t, const std::string& comment);

/// Reads a table. InputError(path, line, ...) when BEGIN/header/[END] are missing, the unit is not MM,
/// NR is not 0, 1, 2, ..., a required column is missing or anything but ';' comments follows [END].
TncTable parseTncTable(const std::string& path, std::string_view text, const std::vector<std::string>& required);

}  // namespace cnccomp::controllers::heidenhain
