#include "cnccomp/io/csv.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/text_util.hpp"
#include "cnccomp/machine.hpp"

namespace cnccomp::io {

void requireRegularFile(const std::string& path) {
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0) throw InputError(path, 0, fmt::format("cannot open file: {}", std::strerror(errno)));
    if (S_ISDIR(st.st_mode)) throw InputError(path, 0, "is a folder, not a file");
    const char* kind = S_ISFIFO(st.st_mode)                          ? "a FIFO (named pipe)"
                       : S_ISSOCK(st.st_mode)                        ? "a socket"
                       : S_ISCHR(st.st_mode) || S_ISBLK(st.st_mode) ? "a device"
                                                                     : "not a regular file";
    if (!S_ISREG(st.st_mode)) throw InputError(path, 0, fmt::format("is {}, not a file; only regular files are read", kind));
}

std::string separatorName(char separator) { return separator == '\t' ? "tab" : std::string(1, separator); }

CsvReader::CsvReader(const std::string& path) : path_(path) {
    requireRegularFile(path);
    file_ = std::make_unique<std::ifstream>(path, std::ios::binary);
    if (!*file_) throw InputError(path, 0, "cannot open file");
}

CsvReader::CsvReader(std::string_view text, const std::string& name) : path_(name), text_(text) {}

CsvReader::~CsvReader() = default;

bool CsvReader::nextLine(std::string_view& out) {
    if (file_) {
        if (!std::getline(*file_, buffer_)) {
            if (file_->bad()) throw InputError(path_, line_ + 1, "read error");
            return false;
        }
        out = buffer_;
    } else {
        if (textPos_ >= text_.size()) return false;
        const size_t end = text_.find('\n', textPos_);
        out = text_.substr(textPos_, end == std::string_view::npos ? std::string_view::npos : end - textPos_);
        textPos_ = end == std::string_view::npos ? text_.size() : end + 1;
    }
    ++line_;
    if (line_ == 1) {
        if (out.size() >= 2 && ((out[0] == '\xff' && out[1] == '\xfe') || (out[0] == '\xfe' && out[1] == '\xff')))
            throw InputError(path_, 1, "UTF-16 text; save the file as UTF-8 (or ASCII) CSV");
        out = withoutByteOrderMark(out);
    }
    if (out.find('\0') != std::string_view::npos) throw InputError(path_, line_, "binary data where CSV text was expected");
    return true;
}

void CsvReader::split(std::string_view line, std::vector<std::string>& cells) const {
    size_t used = 0;
    const auto put = [&](std::string_view s) {
        if (used < cells.size()) cells[used].assign(s.data(), s.size());
        else cells.emplace_back(s);
        ++used;
    };
    size_t i = 0;
    std::string quoted;
    while (true) {
        size_t j = i;
        while (j < line.size() && (line[j] == ' ' || line[j] == '\t') && line[j] != separator_) ++j;
        if (j < line.size() && line[j] == '"') {
            // Quoted cell: up to the closing quote, "" standing for one quote; then only blanks before the separator.
            quoted.clear();
            size_t k = j + 1;
            bool closed = false;
            while (k < line.size()) {
                if (line[k] == '"') {
                    if (k + 1 < line.size() && line[k + 1] == '"') {
                        quoted.push_back('"');
                        k += 2;
                        continue;
                    }
                    closed = true;
                    ++k;
                    break;
                }
                quoted.push_back(line[k++]);
            }
            if (!closed) throw InputError(path_, line_, "a quoted cell is not closed on its line (\" missing)");
            while (k < line.size() && line[k] != separator_ && (line[k] == ' ' || line[k] == '\t' || line[k] == '\r')) ++k;
            if (k < line.size() && line[k] != separator_)
                throw InputError(path_, line_, fmt::format("text after a quoted cell; expected the separator '{}'",
                                                           separatorName(separator_)));
            put(trim(quoted));
            if (k >= line.size()) break;
            i = k + 1;
            continue;
        }
        const size_t at = line.find(separator_, i);
        put(trim(line.substr(i, at == std::string_view::npos ? std::string_view::npos : at - i)));
        if (at == std::string_view::npos) break;
        i = at + 1;
    }
    cells.resize(used);
}

bool CsvReader::skipBlankOrComment(std::string_view s) {
    if (s.empty()) return true;
    if (s.front() != '#') return false;
    const std::string_view body = trim(s.substr(1));
    const size_t colon = body.find(':');
    if (colon != std::string_view::npos && colon > 0)
        comments_.push_back({std::string(trim(body.substr(0, colon))), std::string(trim(body.substr(colon + 1))), line_});
    return true;
}

const CsvRow& CsvReader::header() {
    if (haveHeader_) return header_;
    std::string_view raw;
    while (nextLine(raw)) {
        const std::string_view s = trim(raw);
        if (!s.empty() && s.front() == '#') preamble_.push_back({line_, {std::string(s)}});
        if (skipBlankOrComment(s)) continue;
        // The separator: ';' or a tab outside quotes, else ','.
        bool inQuote = false, semicolon = false, tab = false;
        for (const char c : s) {
            if (c == '"') inQuote = !inQuote;
            else if (!inQuote && c == ';') semicolon = true;
            else if (!inQuote && c == '\t') tab = true;
        }
        separator_ = semicolon ? ';' : tab ? '\t' : ',';
        header_.line = line_;
        split(s, header_.cells);
        haveHeader_ = true;
        return header_;
    }
    throw InputError(path_, line_, "empty file; expected a CSV header line");
}

bool CsvReader::next(CsvRow& row) {
    header();
    std::string_view raw;
    while (nextLine(raw)) {
        const std::string_view s = trim(raw);
        if (skipBlankOrComment(s)) continue;
        row.line = line_;
        split(s, row.cells);
        if (row.cells.size() > header_.cells.size()) {
            const bool decimalComma = separator_ == ',' && std::any_of(row.cells.begin(), row.cells.end(), [](const std::string& c) {
                return !c.empty() && std::all_of(c.begin(), c.end(), [](char ch) { return ch >= '0' && ch <= '9'; });
            });
            throw InputError(path_, line_,
                             fmt::format("{} cells, but the header (line {}) has {} columns (separator '{}'){}",
                                         row.cells.size(), header_.line, header_.cells.size(), separatorName(separator_),
                                         decimalComma ? "; a decimal comma? With ',' between cells numbers need a decimal "
                                                        "point, or separate the cells with ';'"
                                                      : ""));
        }
        return true;
    }
    return false;
}

std::optional<double> parseCsvNumber(std::string_view cell, bool decimalComma) {
    if (decimalComma && cell.find(',') != std::string_view::npos) {
        if (cell.find('.') != std::string_view::npos || std::count(cell.begin(), cell.end(), ',') != 1) return std::nullopt;
        std::string s(cell);
        std::replace(s.begin(), s.end(), ',', '.');
        return parseNumber(s);
    }
    return parseNumber(cell);
}

int CsvTable::column(const std::string& name) const {
    for (size_t i = 0; i < header.cells.size(); ++i)
        if (header.cells[i] == name) return static_cast<int>(i);
    return -1;
}

int CsvTable::requireColumn(const std::string& name) const {
    const int c = column(name);
    if (c < 0) {
        std::string found;
        for (const std::string& h : header.cells) found += (found.empty() ? "'" : ", '") + h + "'";
        throw InputError(path, header.line, fmt::format("missing column '{}' in the header (found {}; separator '{}')", name,
                                                        found, separatorName(separator)));
    }
    return c;
}

const std::string& CsvTable::cell(const CsvRow& row, int c) const {
    static const std::string empty;
    return c >= 0 && c < static_cast<int>(row.cells.size()) ? row.cells[c] : empty;
}

std::optional<double> CsvTable::number(const CsvRow& row, int c) const {
    const std::string& s = cell(row, c);
    if (s.empty()) return std::nullopt;
    const auto v = parseCsvNumber(s, separator != ',');
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

namespace {

CsvTable readAll(CsvReader& r) {
    CsvTable t;
    t.path = r.path();
    t.header = r.header();
    t.separator = r.separator();
    CsvRow row;
    while (r.next(row)) t.rows.push_back(row);
    t.preamble = r.preamble();
    return t;
}

}  // namespace

CsvTable readCsv(const std::string& path) {
    CsvReader r(path);
    return readAll(r);
}

CsvTable parseCsv(std::string_view text, const std::string& name) {
    CsvReader r(text, name);
    return readAll(r);
}

std::string axisColumn(const MachineModel& m, int axis) {
    return m.axisNames[static_cast<size_t>(axis)] + (m.axisLink(axis).kind == AxisKind::Rotary ? "_deg" : "_mm");
}

}  // namespace cnccomp::io
