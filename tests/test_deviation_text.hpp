#pragma once
// A deviation CSV read as plain text, for tests that need an oracle independent of src/cnccomp/io/deviation_csv and
// of the deviation vector: what the file says, column by column.
#include <cmath>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "test_support.hpp"

namespace cnccomp::test {

/// One row of a deviation CSV as its text writes it (`name,alias,value,unit[,alias_value]`).
struct DeviationRowText {
    std::string name, alias, unit;
    double value = NAN;       ///< under `name` (under `alias` when `name` is empty)
    double aliasValue = NAN;  ///< the `alias_value` column; NaN when absent or empty
};

/// The rows of a deviation CSV (split at commas, header skipped), keyed by the name column (the alias when it is empty).
inline std::map<std::string, DeviationRowText> deviationRowsAsWritten(const std::string& path) {
    std::map<std::string, DeviationRowText> rows;
    std::istringstream in(readText(path));
    std::string line;
    std::getline(in, line);  // header
    while (std::getline(in, line)) {
        if (!line.empty() && line.back() == '\r') line.pop_back();
        if (line.empty() || line[0] == '#') continue;
        std::vector<std::string> cell;
        std::istringstream c(line);
        for (std::string x; std::getline(c, x, ',');) cell.push_back(x);
        if (cell.size() < 4) continue;
        DeviationRowText r;
        r.name = cell[0], r.alias = cell[1], r.value = std::stod(cell[2]), r.unit = cell[3];
        if (cell.size() > 4 && !cell[4].empty()) r.aliasValue = std::stod(cell[4]);
        rows[r.name.empty() ? r.alias : r.name] = r;
    }
    return rows;
}

}  // namespace cnccomp::test
