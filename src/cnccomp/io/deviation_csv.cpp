#include "cnccomp/io/deviation_csv.hpp"

#include <cmath>
#include <map>
#include <ostream>
#include <sstream>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/csv.hpp"
#include "cnccomp/io/text_util.hpp"
#include "cnccomp/units.hpp"

namespace cnccomp {
namespace {

// "EXC[3]" → ("EXC", 3); plain names give index -1.
std::pair<std::string, int> splitIndex(const std::string& s, const std::string& path, int line) {
    const size_t open = s.find('[');
    if (open == std::string::npos) return {s, -1};
    if (s.back() != ']') throw InputError(path, line, fmt::format("'{}': expected NAME[index]", s));
    const auto k = parseNumber(std::string_view(s).substr(open + 1, s.size() - open - 2));
    if (!k || *k < 0 || *k != std::floor(*k)) throw InputError(path, line, fmt::format("'{}': bad coefficient index", s));
    return {s.substr(0, open), static_cast<int>(*k)};
}

}  // namespace

DeviationSet readDeviationCsv(const std::string& path, const MachineModel& machine) {
    const CsvTable t = readCsv(path);
    const int cName = t.column("name"), cAlias = t.column("alias");
    if (cName < 0 && cAlias < 0) throw InputError(path, t.header.line, "header needs a 'name' or 'alias' column");
    const int cValue = t.requireColumn("value"), cUnit = t.requireColumn("unit");
    DeviationSet set(machine);
    std::map<std::pair<int, int>, int> firstLine;  // (deviation, coefficient) → line: a value given twice is an error
    for (const CsvRow& row : t.rows) {
        const std::string& rawName = t.cell(row, cName);
        const std::string& rawAlias = t.cell(row, cAlias);
        if (rawName.empty() && rawAlias.empty()) throw InputError(path, row.line, "row has neither name nor alias");
        int index = -1, coef = -1;
        for (const std::string* s : {&rawName, &rawAlias}) {
            if (s->empty()) continue;
            const auto [base, k] = splitIndex(*s, path, row.line);
            const int i = machine.deviationIndex(base);
            if (i < 0)
                throw InputError(path, row.line,
                                 fmt::format("unknown deviation '{}' for machine '{}'", base, machine.name));
            if (index >= 0 && (i != index || k != coef))
                throw InputError(path, row.line, fmt::format("name '{}' and alias '{}' are different deviations",
                                                             rawName, rawAlias));
            index = i;
            coef = k;
        }
        const DeviationDef& d = machine.deviations[index];
        if (const auto [it, fresh] = firstLine.emplace(std::pair{index, coef}, row.line); !fresh)
            throw InputError(path, row.line,
                             fmt::format("{}{} is given twice (first on line {}); which value is meant?", d.name,
                                         coef >= 0 ? fmt::format("[{}]", coef) : "", it->second));
        if (d.kind == DeviationKind::Location && coef >= 0)
            throw InputError(path, row.line, fmt::format("'{}' is a location error and takes no [index]", d.name));
        if (d.kind == DeviationKind::Component && (coef < 0 || coef >= d.size()))
            throw InputError(path, row.line,
                             fmt::format("component error '{}' needs a coefficient index 0..{}", d.name, d.size() - 1));
        const std::string& unitText = t.cell(row, cUnit);
        const auto unit = parseUnit(unitText);
        if (!unit) throw InputError(path, row.line, fmt::format("unknown unit '{}' (um, mm, arcsec, urad, um/m, rad, deg)", unitText));
        const Quantity want = d.isAngle() ? Quantity::Angle : Quantity::Length;
        if (unit->quantity != want)
            throw InputError(path, row.line, fmt::format("'{}' is {}; unit '{}' does not fit", d.name,
                                                         d.isAngle() ? "an angle" : "a length", unitText));
        const double v = t.requireNumber(row, cValue);
        set.values[d.offset + std::max(coef, 0)] = v * unit->toInternal;
        set.present[index] = 1;
    }
    return set;
}

std::string formatDeviationCsv(const DeviationSet& set, bool all) {
    std::ostringstream out;
    out << "name,alias,value,unit\n";
    const MachineModel& m = set.machine();
    for (size_t i = 0; i < m.deviations.size(); ++i) {
        if (!all && !set.present[i]) continue;
        const DeviationDef& d = m.deviations[i];
        const double scale = d.isAngle() ? 1.0 / kArcsec : 1.0 / kUm;
        const char* unit = d.isAngle() ? "arcsec" : "um";
        if (d.kind == DeviationKind::Location) {
            out << fmt::format("{},{},{:.6f},{}\n", d.name, d.alias, set.values[d.offset] * scale, unit);
        } else {
            for (int k = 0; k < d.size(); ++k)
                out << fmt::format("{}[{}],{},{:.6f},{}\n", d.name, k, d.alias.empty() ? "" : d.alias + "[" + std::to_string(k) + "]",
                                   set.values[d.offset + k] * scale, unit);
        }
    }
    return out.str();
}

void writeDeviationCsv(const std::string& path, const DeviationSet& set, bool all) {
    const std::string text = formatDeviationCsv(set, all);
    writeFileAtomically(path, [&](std::ostream& o) { o << text; });
}

}  // namespace cnccomp
