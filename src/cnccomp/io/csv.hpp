#pragma once
// Minimal CSV reading with line numbers: comma separated, no quoting, '#' lines and blank lines skipped.
#include <optional>
#include <string>
#include <vector>

namespace cnccomp {

struct MachineModel;

struct CsvRow {
    int line = 0;
    std::vector<std::string> cells;
};

struct CsvTable {
    std::string path;
    CsvRow header;
    std::vector<CsvRow> rows;
    /// Column index by header name, or -1.
    int column(const std::string& name) const;
    /// Column index by header name; throws InputError naming the file when missing.
    int requireColumn(const std::string& name) const;
    /// Cell as a finite number; throws InputError with file:line when not. Empty cells give nullopt.
    std::optional<double> number(const CsvRow& row, int column) const;
    double requireNumber(const CsvRow& row, int column) const;
    const std::string& cell(const CsvRow& row, int column) const;
};

/// Reads a CSV file whose first non-comment line is the header. Throws InputError on a missing file,
/// binary content, or rows with more cells than the header.
CsvTable readCsv(const std::string& path);

/// Column of machine axis `axis` in cnccomp's CSV files: its name and unit, e.g. "X_mm", "C_deg".
std::string axisColumn(const MachineModel& m, int axis);

}  // namespace cnccomp
