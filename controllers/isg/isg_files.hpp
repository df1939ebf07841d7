#pragma once
// ISG / Beckhoff TwinCAT CNC TF5280 volumetric compensation files (Beckhoff infosys, TF5280 "ISG CSV format",
// "List of parameters supported", P-VOLC parameters):
// - the compensation list (volcomp.lis): logical axis numbers of the participating axes ("X 1"), the kinematic
//   chain ("chain CAYXZ": from the workpiece over the machine origin to the tool tip), the number of workpiece axes, the parameter files and their format; '#' comments;
// - the ISG_CSV parameter file: a header line naming the columns (arguments such as X, and error parameters such
//   as X0C or EXX), data rows below, "//" line comments, and '#' starting a new block with its own header.
//   Values in mm and rad, arguments in mm and degrees.
#include <map>
#include <string>
#include <vector>

namespace cnccomp::controllers::isg {

struct IsgConfig {
    std::map<char, int> axisNumber;   ///< axis letter → logical axis number
    std::string chain;                ///< axis letters, workpiece → machine origin → tool tip (TF5240)
    int workpieceAxes = 0;
    std::vector<std::pair<std::string, std::string>> files;  ///< file name, format
    /// P-VOLC-00009 `negate` (TF5280 "Modification of compensation values (optional)"): the Cartesian axes (of X Y Z)
    /// whose computed compensation value the control negates, e.g. "XY"; `set_to_zero`: those whose value it sets to
    /// 0. cnccomp writes neither (the values are meant to be used as computed, which its files' header states) and
    /// reads both, so that verify sees what a list that sets them does.
    std::string negate{}, setToZero{};
};
std::string formatIsgConfig(const IsgConfig& c, const std::string& header);
/// InputError(file:line) on unknown keys, bad numbers, a format other than ISG_CSV.
IsgConfig parseIsgConfig(const std::string& text, const std::string& name);

struct IsgBlock {
    int headerLine = 0;
    std::vector<std::string> columns;
    std::vector<std::vector<double>> rows;
    std::vector<int> rowLines;
};
/// Blocks of an ISG_CSV file. InputError(file:line) on rows with the wrong number of fields, non-numbers,
/// repeated column names (the controller's error 70469), a block without rows.
std::vector<IsgBlock> parseIsgCsv(const std::string& text, const std::string& name);

}  // namespace cnccomp::controllers::isg
