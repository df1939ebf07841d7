#include "cnccomp/io/laser_csv.hpp"

#include <algorithm>
#include <cctype>
#include <map>
#include <optional>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/csv.hpp"

namespace cnccomp::io {

// Internals in a named namespace (not anonymous): the core may be compiled as unity units.
namespace laser_csv_detail {

std::string lower(std::string s) {
    std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return s;
}

/// +1 forward (↑), −1 reverse (↓), 0 unknown.
int directionOf(const std::string& label) {
    const std::string s = lower(label);
    if (s == "+" || s == "fwd" || s == "forward") return 1;
    if (s == "-" || s == "rev" || s == "reverse") return -1;
    return 0;
}

struct Run {
    std::string label;
    int line = 0;                     ///< first row of the run
    std::map<double, double> values;  ///< target → deviation, µm
};

LaserCsvFile readFrom(CsvReader& reader, const LaserCsvOptions& o) {
    const std::string& path = reader.path();
    if (o.deviationUnit != "um" && o.deviationUnit != "mm")
        throw InputError(path, 0, fmt::format("deviation unit '{}'; expected um or mm", o.deviationUnit));
    const double toUm = o.deviationUnit == "mm" ? 1000.0 : 1.0;
    const std::string devName = o.deviationColumn.empty() ? "deviation_" + o.deviationUnit : o.deviationColumn;
    const CsvRow& header = reader.header();
    const auto column = [&](const std::string& name) {
        for (size_t k = 0; k < header.cells.size(); ++k)
            if (header.cells[k] == name) return static_cast<int>(k);
        throw InputError(path, header.line,
                         fmt::format("no column '{}'; expected the columns {}, {}, {}, {} (found: {})", name,
                                     o.targetColumn, o.runColumn, o.directionColumn, devName,
                                     fmt::format("{}", fmt::join(header.cells, ", "))));
    };
    const int cTarget = column(o.targetColumn), cRun = column(o.runColumn), cDir = column(o.directionColumn),
              cDev = column(devName);
    const bool decimalComma = reader.separator() == ';' || reader.separator() == '\t';
    const auto number = [&](const CsvRow& r, int c, const std::string& what) {
        const std::string cell = c < static_cast<int>(r.cells.size()) ? r.cells[static_cast<size_t>(c)] : "";
        const auto v = parseCsvNumber(cell, decimalComma);
        if (!v)
            throw InputError(path, r.line, fmt::format("{} '{}' in column '{}' is not a number; expected a number",
                                                       what, cell, header.cells[static_cast<size_t>(c)]));
        return *v;
    };
    std::vector<Run> runs[2];  // [0] forward, [1] reverse
    std::map<double, int> targets;  // target → first line
    CsvRow r;
    int rows = 0;
    while (reader.next(r)) {
        ++rows;
        const auto cell = [&](int c) -> std::string {
            return c < static_cast<int>(r.cells.size()) ? r.cells[static_cast<size_t>(c)] : std::string();
        };
        const double target = number(r, cTarget, "target");
        const double dev = number(r, cDev, "deviation") * toUm;
        const std::string dirLabel = cell(cDir);
        const int dir = directionOf(dirLabel);
        if (dir == 0)
            throw InputError(path, r.line, fmt::format("direction '{}'; expected + or - (also fwd/rev, forward/reverse)",
                                                       dirLabel));
        const std::string label = cell(cRun);
        if (label.empty()) throw InputError(path, r.line, fmt::format("empty run label in column '{}'", o.runColumn));
        auto& list = runs[dir > 0 ? 0 : 1];
        auto it = std::find_if(list.begin(), list.end(), [&](const Run& x) { return x.label == label; });
        if (it == list.end()) {
            list.push_back(Run{label, r.line, {}});
            it = list.end() - 1;
        }
        if (!it->values.emplace(target, dev).second)
            throw InputError(path, r.line, fmt::format("run {} {} has a second reading at target {} mm; expected one "
                                                       "per run, direction and target", label,
                                                       dir > 0 ? "forward" : "reverse", target));
        targets.emplace(target, r.line);
    }
    if (rows == 0) throw InputError(path, header.line, "no readings after the header");

    LaserCsvFile out;
    out.runs.source = path;
    for (const auto& [t, line] : targets) out.runs.targets.push_back(t);
    for (int d = 0; d < 2; ++d)
        for (const Run& run : runs[d]) {
            std::vector<double> values;
            for (const double t : out.runs.targets) {
                const auto v = run.values.find(t);
                if (v == run.values.end())
                    throw InputError(path, run.line,
                                     fmt::format("run {} {} (from this line) has no reading at target {} mm (line {} "
                                                 "has that target); expected every run to cover every target",
                                                 run.label, d == 0 ? "forward" : "reverse", t, targets.at(t)));
                values.push_back(v->second);
            }
            (d == 0 ? out.runs.forward : out.runs.reverse).push_back(std::move(values));
        }

    std::string fileAxis;
    int axisLine = 0;
    for (const CsvComment& c : reader.comments()) {
        const std::string key = lower(c.key);
        if (key == "axis") {
            fileAxis = c.value;
            axisLine = c.line;
        } else if (key == "environment-compensated") {
            const std::string v = lower(c.value);
            if (v != "yes" && v != "no")
                throw InputError(path, c.line,
                                 fmt::format("environment-compensated: '{}'; expected yes or no", c.value));
            out.runs.environmentCompensated = v == "yes";
            out.environmentStated = true;
        }
    }
    if (!o.axis.empty() && !fileAxis.empty() && o.axis != fileAxis)
        throw InputError(path, axisLine, fmt::format("the file is of axis {} but axis {} was asked for", fileAxis,
                                                     o.axis));
    out.runs.axis = o.axis.empty() ? fileAxis : o.axis;
    const bool name = !out.runs.axis.empty() && std::all_of(out.runs.axis.begin(), out.runs.axis.end(), [](char ch) {
        return std::isalnum(static_cast<unsigned char>(ch)) != 0;
    });
    if (out.runs.axis.empty())
        throw InputError(path, 0, "no axis name; expected a '# axis: X' line in the file or the axis option");
    if (!name)
        throw InputError(path, axisLine, fmt::format("axis name '{}'; expected letters or digits", out.runs.axis));
    return out;
}

}  // namespace laser_csv_detail

using laser_csv_detail::readFrom;

LaserCsvFile readLaserCsv(const std::string& path, const LaserCsvOptions& options) {
    CsvReader reader(path);
    return readFrom(reader, options);
}

LaserCsvFile parseLaserCsv(std::string_view text, const std::string& name, const LaserCsvOptions& options) {
    CsvReader reader(text, name);
    return readFrom(reader, options);
}

}  // namespace cnccomp::io
