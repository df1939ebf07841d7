#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/deviation_range.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <map>
#include <ostream>
#include <sstream>

#include <Eigen/LU>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include "cnccomp/error.hpp"
#include "cnccomp/iso_names.hpp"
#include "cnccomp/io/csv.hpp"
#include "cnccomp/io/text_util.hpp"
#include "cnccomp/units.hpp"

namespace cnccomp::io {
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

/// The format line cnccomp writes first (before any header comment of a backend is fine too): from it on, location
/// errors under ISO names are ISO 230-1 values (iso_names.hpp), not the link values files carried before 2026-11-23.
constexpr const char* kFormatLine = "# cnccomp-deviations/2: location errors under ISO 230-1 names are ISO values (iso_names.hpp)";
constexpr const char* kFormatTag = "# cnccomp-deviations/";

/// True when one of the comment lines before the header is the format line (any version tag).
bool hasFormatLine(const CsvTable& t) {
    return std::any_of(t.preamble.begin(), t.preamble.end(), [](const CsvRow& c) { return c.cells[0].rfind(kFormatTag, 0) == 0; });
}

struct Given {
    int line = 0;
    bool iso = true;        ///< value under the ISO name (else under the alias)
    double value = 0;       ///< internal units
    bool hasAliasValue = false;
    double aliasValue = 0, unit = 1;  ///< internal units; unit = internal units per file unit of the row
};

/// A file in the layout cnccomp wrote before its ISO names took ISO 230-1's meaning (no format line, no alias_value
/// column) whose location rows would describe another machine under the old meaning (every value the link's own error
/// component, unlisted ones zero) is refused with the conversion: the ISO values of the old geometry.
void refuseOldMeaning(const std::string& path, const CsvTable& t, bool aliasValueColumn, const MachineModel& machine,
                      const std::map<std::pair<int, int>, Given>& given, const DeviationSet& set) {
    if (aliasValueColumn || given.empty() || hasFormatLine(t)) return;
    DeviationSet old(machine);
    old.values = set.values;
    bool anyLocationName = false;
    int firstLine = 0;
    for (const DeviationDef& d : machine.deviations)
        if (d.kind == DeviationKind::Location) old.values[d.offset] = 0;
    for (const auto& [key, g] : given) {
        const DeviationDef& d = machine.deviations[static_cast<size_t>(key.first)];
        if (d.kind != DeviationKind::Location) continue;
        if (!g.iso) {
            old.values[d.offset] = g.value * d.aliasSign;  // an alias names the paper's value in either meaning
            continue;
        }
        old.values[d.offset] = g.value;
        anyLocationName = true;
        if (firstLine == 0 || g.line < firstLine) firstLine = g.line;
    }
    if (!anyLocationName) return;
    std::vector<std::string> changed, conversion;
    for (int i = 0; i < static_cast<int>(machine.deviations.size()); ++i) {
        const DeviationDef& d = machine.deviations[static_cast<size_t>(i)];
        if (d.kind != DeviationKind::Location) continue;
        const double scale = d.isAngle() ? kArcsec : kUm;
        const double now = set.isoValue(i), before = old.isoValue(i);
        if (std::abs(now - before) > 1e-7 * scale) changed.push_back(d.name);
        if (std::abs(before) > 1e-9 * scale)
            conversion.push_back(fmt::format("{},,{:.6f},{}", d.name, before / scale, d.isAngle() ? "arcsec" : "um"));
    }
    if (changed.empty()) return;
    std::string rows;
    for (const std::string& c : conversion) rows += "\n    " + c;
    throw InputError(
        path, firstLine > 0 ? firstLine : t.header.line,
        fmt::format("this deviation file has no format line and no alias_value column, the layout cnccomp wrote before "
                    "its names took ISO 230-1's meaning (before, a name's value was its link's own error component); on "
                    "machine '{}' that changes {} (the geometry differs). If the values are ISO 230-1 values, add the "
                    "line '{}' at the top. If the file was written by cnccomp before that change, replace its location "
                    "rows by the ISO values of the same geometry and add that line:{}",
                    machine.name, fmt::join(changed, ", "), kFormatLine, rows.empty() ? "\n    (every location error zero)" : rows));
}

/// A reversal row: `B<axis>` (one letter after the B) that is not a deviation of the machine. ISO 230-1 names all begin
/// with E (EXX, EC0Y, EB0Z), so B + an axis letter cannot be one of them; nor is it an axis name.
bool isReversalName(const MachineModel& machine, const std::string& name) {
    return name.size() == 2 && name[0] == 'B' && std::isupper(static_cast<unsigned char>(name[1])) &&
           machine.deviationIndex(name) < 0;
}

void readReversalRow(const std::string& path, const CsvTable& t, const CsvRow& row, const std::string& name,
                     const std::string& other, int cValue, int cUnit, DeviationSet& set, std::map<int, int>& lines) {
    const MachineModel& machine = set.machine();
    const std::string axis = name.substr(1);
    const int a = machine.axisIndex(axis);
    if (a < 0)
        throw InputError(path, row.line,
                         fmt::format("'{}': machine '{}' has no axis {} (a row B<axis> is the reversal value of a linear "
                                     "axis; axes: {})", name, machine.name, axis, fmt::join(machine.axisNames, ", ")));
    if (machine.axisLink(a).kind != AxisKind::Linear)
        throw InputError(path, row.line,
                         fmt::format("'{}': axis {} of machine '{}' is rotary; reversal values (ISO 230-2) are read for "
                                     "linear axes only", name, axis, machine.name));
    if (!other.empty() && other != name)
        throw InputError(path, row.line, fmt::format("reversal row '{}' takes no alias ('{}')", name, other));
    const std::string& unitText = t.cell(row, cUnit);
    const auto unit = parseUnit(unitText);
    if (!unit || unit->quantity != Quantity::Length)
        throw InputError(path, row.line, fmt::format("'{}' is a length (reversal value); unit '{}' does not fit (um, mm)",
                                                     name, unitText));
    const double value = t.requireNumber(row, cValue) * unit->toInternal;
    if (!std::isfinite(value) || std::abs(value) > kMaxDeviationLength)
        throw InputError(path, row.line, fmt::format("'{}' = {:g} mm is beyond any machine's reversal (at most ±{:g} mm); "
                                                     "check the value and its unit", name, value, kMaxDeviationLength));
    if (const auto it = lines.find(a); it != lines.end())
        throw InputError(path, row.line, fmt::format("{} is given twice (first on line {}); which value is meant?", name,
                                                     it->second));
    lines[a] = row.line;
    set.setReversal(axis, value);
}

}  // namespace

std::string deviationRangeProblem(const DeviationDef& d, double value) {
    if (!std::isfinite(value)) return fmt::format("'{}' is not a finite number", d.name);
    if (d.isAngle() ? std::abs(value) <= kMaxDeviationAngle : std::abs(value) <= kMaxDeviationLength) return {};
    return d.isAngle()
               ? fmt::format("'{}' = {:g} arcsec ({:g} deg) is beyond any machine's deviation (at most ±{:g} arcsec = ±1 deg); "
                             "check the value and its unit",
                             d.name, value / kArcsec, value / kDeg, kMaxDeviationAngle / kArcsec)
               : fmt::format("'{}' = {:g} mm is beyond any machine's deviation (at most ±{:g} mm); check the value and its "
                             "unit",
                             d.name, value, kMaxDeviationLength);
}

DeviationSet readDeviationCsv(const std::string& path, const MachineModel& machine) {
    const CsvTable t = readCsv(path);
    const int cName = t.column("name"), cAlias = t.column("alias"), cAliasValue = t.column("alias_value");
    if (cName < 0 && cAlias < 0) throw InputError(path, t.header.line, "header needs a 'name' or 'alias' column");
    const int cValue = t.requireColumn("value"), cUnit = t.requireColumn("unit");
    DeviationSet set(machine);
    std::map<std::pair<int, int>, Given> given;  // (deviation, coefficient) → row
    std::map<int, int> reversalLines;            // axis → line of its reversal row
    int isoRows = 0, aliasRows = 0;
    for (const CsvRow& row : t.rows) {
        const std::string& rawName = t.cell(row, cName);
        const std::string& rawAlias = t.cell(row, cAlias);
        if (rawName.empty() && rawAlias.empty()) throw InputError(path, row.line, "row has neither name nor alias");
        if (const std::string& rn = rawName.empty() ? rawAlias : rawName; isReversalName(machine, rn)) {
            readReversalRow(path, t, row, rn, rawName.empty() ? rawName : rawAlias, cValue, cUnit, set, reversalLines);
            continue;
        }
        int index = -1, coef = -1;
        bool iso = true;
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
            if (index < 0) iso = machine.deviations[static_cast<size_t>(i)].name == base;  // the value's symbol
            index = i;
            coef = k;
        }
        const DeviationDef& d = machine.deviations[static_cast<size_t>(index)];
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
        Given g;
        g.line = row.line;
        g.iso = iso;
        g.unit = unit->toInternal;
        g.value = t.requireNumber(row, cValue) * unit->toInternal;
        if (const std::string why = deviationRangeProblem(d, g.value); !why.empty()) throw InputError(path, row.line, why);
        const bool both = !rawName.empty() && !rawAlias.empty();
        if (const auto av = t.number(row, cAliasValue); av && !d.alias.empty()) {
            g.hasAliasValue = true;
            g.aliasValue = *av * unit->toInternal;
        } else if (both && aliasDiffersFromName(machine, index)) {
            throw InputError(path, row.line,
                             fmt::format("'{}' (ISO 230-1) and '{}' (the paper's symbol) give different numbers for "
                                         "the same geometry ({}{}); give the value under one of them, or add the "
                                         "alias_value column that cnccomp writes",
                                         d.name, d.alias,
                                         d.kind == DeviationKind::Location ? isoMeaningText(machine, index) : d.name,
                                         d.aliasSign < 0 ? fmt::format("; {} is minus the link value", d.alias) : ""));
        }
        const auto key = std::make_pair(index, std::max(coef, 0));
        if (const auto it = given.find(key); it != given.end())
            throw InputError(path, row.line,
                             fmt::format("{}{} is given twice (first on line {}); which value is meant?", d.name,
                                         coef >= 0 ? fmt::format("[{}]", coef) : "", it->second.line));
        given[key] = g;
        (iso ? isoRows : aliasRows) += 1;
        set.present[static_cast<size_t>(index)] = 1;
    }

    // Component coefficients: the link value directly.
    std::vector<int> loc, column(machine.deviations.size(), -1);
    for (int i = 0; i < static_cast<int>(machine.deviations.size()); ++i) {
        const DeviationDef& d = machine.deviations[static_cast<size_t>(i)];
        if (d.kind == DeviationKind::Location) {
            column[static_cast<size_t>(i)] = static_cast<int>(loc.size());
            loc.push_back(i);
            continue;
        }
        for (int k = 0; k < d.size(); ++k)
            if (const auto it = given.find({i, k}); it != given.end())
                set.values[d.offset + k] = it->second.iso ? it->second.value : it->second.value * d.aliasSign;
    }
    // Location errors: one linear equation per deviation — its row, or zero under its ISO name (under its alias when
    // every row of the file uses an alias).
    const bool aliasOnly = isoRows == 0 && aliasRows > 0;
    const int n = static_cast<int>(loc.size());
    if (n > 0 && !given.empty()) {
        Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n);
        Eigen::VectorXd b = Eigen::VectorXd::Zero(n);
        for (int r = 0; r < n; ++r) {
            const int i = loc[static_cast<size_t>(r)];
            const DeviationDef& d = machine.deviations[static_cast<size_t>(i)];
            const auto it = given.find({i, 0});
            const bool iso = it != given.end() ? it->second.iso : !aliasOnly;
            if (it != given.end()) b[r] = it->second.value;
            if (iso)
                for (const DeviationTerm& term : d.isoTerms) A(r, column[static_cast<size_t>(term.deviation)]) += term.coefficient;
            else
                A(r, r) = it != given.end() ? d.aliasSign : 1.0;
        }
        const Eigen::FullPivLU<Eigen::MatrixXd> lu(A);
        if (lu.rank() < n)
            throw InputError(path, t.header.line,
                             "the ISO names and aliases given do not determine the deviations; use one kind of name");
        const Eigen::VectorXd x = lu.solve(b);
        for (int r = 0; r < n; ++r) set.values[machine.deviations[static_cast<size_t>(loc[static_cast<size_t>(r)])].offset] = x[r];
    }
    refuseOldMeaning(path, t, cAliasValue >= 0, machine, given, set);
    for (const auto& [key, g] : given) {
        if (!g.hasAliasValue) continue;
        const DeviationDef& d = machine.deviations[static_cast<size_t>(key.first)];
        const double have = set.aliasValue(key.first, key.second);
        if (std::abs(have - g.aliasValue) > 5e-6 * g.unit + 1e-9 * std::abs(g.aliasValue))
            throw InputError(path, g.line,
                             fmt::format("alias_value of '{}' is {:.6f} but the file's values give {:.6f} for '{}'",
                                         d.name, g.aliasValue / g.unit, have / g.unit, d.alias));
    }
    return set;
}

std::string formatDeviationCsv(const DeviationSet& set, bool all) {
    std::ostringstream out;
    out << kFormatLine << '\n' << "name,alias,value,unit,alias_value\n";
    const MachineModel& m = set.machine();
    for (size_t i = 0; i < m.deviations.size(); ++i) {
        if (!all && !set.present[i]) continue;
        const DeviationDef& d = m.deviations[i];
        const double scale = d.isAngle() ? 1.0 / kArcsec : 1.0 / kUm;
        const char* unit = d.isAngle() ? "arcsec" : "um";
        const int index = static_cast<int>(i);
        const auto aliasCell = [&](int k) {
            return d.alias.empty() ? std::string() : fmt::format("{:.6f}", set.aliasValue(index, k) * scale);
        };
        if (d.kind == DeviationKind::Location) {
            out << fmt::format("{},{},{:.6f},{},{}\n", d.name, d.alias, set.isoValue(index) * scale, unit, aliasCell(0));
        } else {
            for (int k = 0; k < d.size(); ++k)
                out << fmt::format("{}[{}],{},{:.6f},{},{}\n", d.name, k,
                                   d.alias.empty() ? "" : d.alias + "[" + std::to_string(k) + "]",
                                   set.values[d.offset + k] * scale, unit, aliasCell(k));
        }
    }
    // Reversal values (DeviationSet::reversal) after the deviations, only the present ones (also with `all`): a set
    // without them is written as before.
    for (int a = 0; a < m.axisCount(); ++a)
        if (set.reversalPresent[static_cast<size_t>(a)])
            out << fmt::format("B{},,{:.6f},um,\n", m.axisNames[static_cast<size_t>(a)],
                               set.reversal[static_cast<size_t>(a)] / kUm);
    return out.str();
}

void writeDeviationCsv(const std::string& path, const DeviationSet& set, bool all) {
    const std::string text = formatDeviationCsv(set, all);
    writeFileAtomically(path, [&](std::ostream& o) { o << text; });
}

}  // namespace cnccomp::io
