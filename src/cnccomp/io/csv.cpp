#include "cnccomp/io/csv.hpp"

#include <cmath>
#include <fstream>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/text_util.hpp"
#include "cnccomp/machine.hpp"

namespace cnccomp {
namespace {

std::vector<std::string> split(std::string_view line) {
    std::vector<std::string> out;
    size_t start = 0;
    while (true) {
        const size_t comma = line.find(',', start);
        out.emplace_back(trim(line.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start)));
        if (comma == std::string_view::npos) break;
        start = comma + 1;
    }
    return out;
}

}  // namespace

int CsvTable::column(const std::string& name) const {
    for (size_t i = 0; i < header.cells.size(); ++i)
        if (header.cells[i] == name) return static_cast<int>(i);
    return -1;
}

int CsvTable::requireColumn(const std::string& name) const {
    const int c = column(name);
    if (c < 0) throw InputError(path, header.line, fmt::format("missing column '{}' in the header", name));
    return c;
}

const std::string& CsvTable::cell(const CsvRow& row, int c) const {
    static const std::string empty;
    return c >= 0 && c < static_cast<int>(row.cells.size()) ? row.cells[c] : empty;
}

std::optional<double> CsvTable::number(const CsvRow& row, int c) const {
    const std::string& s = cell(row, c);
    if (s.empty()) return std::nullopt;
    const auto v = parseNumber(s);
    if (!v || !std::isfinite(*v))
        throw InputError(path, row.line,
                         fmt::format("column '{}': expected a finite number, found '{}'", header.cells[c], s));
    return v;
}

double CsvTable::requireNumber(const CsvRow& row, int c) const {
    const auto v = number(row, c);
    if (!v) throw InputError(path, row.line, fmt::format("column '{}' is empty; a number is expected", header.cells[c]));
    return *v;
}

CsvTable readCsv(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(path, 0, "cannot open file");
    CsvTable t;
    t.path = path;
    std::string line;
    int n = 0;
    bool haveHeader = false;
    while (std::getline(in, line)) {
        ++n;
        if (line.find('\0') != std::string::npos) throw InputError(path, n, "binary data where CSV text was expected");
        const std::string_view s = trim(line);
        if (s.empty() || s.front() == '#') continue;
        CsvRow row{n, split(s)};
        if (!haveHeader) {
            t.header = std::move(row);
            haveHeader = true;
            continue;
        }
        if (row.cells.size() > t.header.cells.size())
            throw InputError(path, n, fmt::format("{} cells, but the header has {} columns", row.cells.size(),
                                                  t.header.cells.size()));
        t.rows.push_back(std::move(row));
    }
    if (!haveHeader) throw InputError(path, n, "empty file; expected a CSV header line");
    return t;
}

std::string axisColumn(const MachineModel& m, int axis) {
    return m.axisNames[static_cast<size_t>(axis)] + (m.axisLink(axis).kind == AxisKind::Rotary ? "_deg" : "_mm");
}

}  // namespace cnccomp
