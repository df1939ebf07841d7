#include "controllers/heidenhain/tnc_table.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/text_util.hpp"

namespace cnccomp::controllers::heidenhain {
using namespace cnccomp::io;

int TncTable::column(const std::string& n) const {
    for (size_t i = 0; i < columns.size(); ++i)
        if (columns[i] == n) return static_cast<int>(i);
    return -1;
}

const std::string& TncTable::cell(size_t row, int c) const {
    static const std::string empty;
    if (c < 0 || row >= rows.size() || c >= static_cast<int>(rows[row].size())) return empty;
    return rows[row][c];
}

std::string formatTncTable(const TncTable& t, const std::string& comment) {
    std::vector<size_t> width(t.columns.size());
    for (size_t c = 0; c < t.columns.size(); ++c) {
        width[c] = t.columns[c].size();
        for (const auto& r : t.rows) width[c] = std::max(width[c], c < r.size() ? r[c].size() : 0);
        width[c] += 2;
    }
    const auto line = [&](const std::vector<std::string>& cells) {
        std::string s;
        for (size_t c = 0; c < t.columns.size(); ++c) {
            const std::string v = c < cells.size() ? cells[c] : "";
            s += c + 1 < t.columns.size() ? fmt::format("{:<{}}", v, width[c]) : v;
        }
        while (!s.empty() && s.back() == ' ') s.pop_back();
        return s + "\n";
    };
    std::string s = fmt::format("BEGIN {} MM\n", t.name);
    s += line(t.columns);
    for (const auto& r : t.rows) s += line(r);
    s += "[END]\n";
    s += comment;
    return s;
}

TncTable parseTncTable(const std::string& path, std::string_view text, const std::vector<std::string>& required) {
    TncTable t;
    t.path = path;
    std::vector<std::string_view> lines;
    for (size_t pos = 0; pos <= text.size();) {
        const size_t eol = text.find('\n', pos);
        std::string_view l = text.substr(pos, eol == std::string_view::npos ? text.size() - pos : eol - pos);
        if (!l.empty() && l.back() == '\r') l.remove_suffix(1);
        if (eol == std::string_view::npos) {
            if (!l.empty()) lines.push_back(l);  // no line after the final line break
            break;
        }
        lines.push_back(l);
        pos = eol + 1;
    }
    for (size_t i = 0; i < lines.size(); ++i)
        for (char ch : lines[i])
            if (static_cast<unsigned char>(ch) < 0x20 && ch != '\t')
                throw InputError(path, static_cast<int>(i) + 1, "binary content: not a TNC table");
    if (lines.empty() || !trim(lines[0]).starts_with("BEGIN "))
        throw InputError(path, 1, "expected 'BEGIN <name> MM' on the first line");
    {
        const std::string_view b = trim(lines[0]);
        const size_t sp = b.rfind(' ');
        const std::string_view unit = trim(b.substr(sp + 1));
        t.name = std::string(trim(b.substr(6, sp > 6 ? sp - 6 : 0)));
        if (t.name.empty()) throw InputError(path, 1, "BEGIN line without a table name");
        if (unit != "MM") throw InputError(path, 1, fmt::format("unit '{}': only MM tables are read", unit));
    }
    if (lines.size() < 2 || trim(lines[1]).empty()) throw InputError(path, 2, "expected the column header line");
    std::vector<size_t> start;
    {
        const std::string_view h = lines[1];
        for (size_t i = 0; i < h.size();) {
            if (h[i] == ' ' || h[i] == '\t') {
                ++i;
                continue;
            }
            const size_t j = std::min(h.find(' ', i), h.size());
            start.push_back(i);
            t.columns.emplace_back(h.substr(i, j - i));
            i = j;
        }
    }
    for (const auto& r : required)
        if (t.column(r) < 0) throw InputError(path, 2, fmt::format("missing column {}", r));
    bool ended = false;
    for (size_t i = 2; i < lines.size(); ++i) {
        const int lineNo = static_cast<int>(i) + 1;
        const std::string_view l = lines[i];
        if (ended) {
            if (!trim(l).empty() && trim(l).front() != ';')
                throw InputError(path, lineNo, "only ';' comment lines may follow [END]");
            continue;
        }
        if (trim(l) == "[END]") {
            ended = true;
            continue;
        }
        if (trim(l).empty()) throw InputError(path, lineNo, "empty line inside the table");
        std::vector<std::string> cells(t.columns.size());
        for (size_t c = 0; c < start.size(); ++c) {
            if (start[c] >= l.size()) break;
            const size_t end = c + 1 < start.size() ? std::min(start[c + 1], l.size()) : l.size();
            cells[c] = std::string(trim(l.substr(start[c], end - start[c])));
        }
        // Text between columns would be cut by the fixed widths: refuse a cell that runs into the next one.
        for (size_t c = 0; c + 1 < start.size(); ++c)
            if (start[c + 1] < l.size() && start[c + 1] > 0 && l[start[c + 1] - 1] != ' ' && l[start[c + 1]] != ' ')
                throw InputError(path, lineNo, fmt::format("a value runs across the start of column {}", t.columns[c + 1]));
        const auto nr = parseNumber(cells[0]);
        if (!nr || *nr != static_cast<double>(t.rows.size()))
            throw InputError(path, lineNo, fmt::format("NR '{}': expected {}", cells[0], t.rows.size()));
        t.rows.push_back(std::move(cells));
        t.lines.push_back(lineNo);
    }
    if (!ended) throw InputError(path, static_cast<int>(lines.size()), "missing [END]");
    return t;
}

}  // namespace cnccomp::controllers::heidenhain
