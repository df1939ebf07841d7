#include "controllers/siemens/siemens_syntax.hpp"

#include <cctype>
#include <cmath>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/text_util.hpp"

namespace cnccomp::controllers::siemens {
using namespace cnccomp::io;
namespace {

bool isVariableChar(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }

std::vector<std::string> splitIndices(std::string_view s) {
    std::vector<std::string> out;
    size_t start = 0;
    for (size_t i = 0; i <= s.size(); ++i)
        if (i == s.size() || s[i] == ',') {
            out.emplace_back(trim(s.substr(start, i - start)));
            start = i + 1;
        }
    return out;
}

}  // namespace

AssignmentFile parseAssignmentFile(const std::string& path, std::string_view text, std::string_view expected) {
    AssignmentFile f;
    f.path = path;
    bool ended = false;
    int lineNo = 0;
    size_t pos = 0;
    while (pos <= text.size()) {
        const size_t eol = text.find('\n', pos);
        const std::string_view raw = text.substr(pos, eol == std::string_view::npos ? text.size() - pos : eol - pos);
        pos = eol == std::string_view::npos ? text.size() + 1 : eol + 1;
        ++lineNo;
        for (char c : raw)
            if (static_cast<unsigned char>(c) < 0x20 && c != '\t' && c != '\r')
                throw InputError(path, lineNo, "binary content: not a Sinumerik text file");
        const std::string_view line = trim(raw);
        if (line.empty()) continue;
        if (f.identifier.empty()) {
            if (line.size() < 4 || line[0] != '%' || line[1] != '_')
                throw InputError(path, lineNo, fmt::format("expected the file identifier (e.g. %_N_NC_CEC_INI), got '{}'", line));
            f.identifier = std::string(line.substr(1));
            if (!expected.empty() && f.identifier != expected)
                throw InputError(path, lineNo, fmt::format("file identifier is %{}, expected %{}", f.identifier, expected));
            continue;
        }
        if (line[0] == ';') continue;
        if (ended) throw InputError(path, lineNo, "text after M17 (the end of the file)");
        if (line == "M17") {
            ended = true;
            continue;
        }
        if (line.starts_with("CHANDATA(") && line.back() == ')') {
            const auto n = parseNumber(line.substr(9, line.size() - 10));
            if (!n || *n < 1 || *n != std::floor(*n)) throw InputError(path, lineNo, "CHANDATA needs a channel number >= 1");
            continue;
        }
        if (line[0] != '$') throw InputError(path, lineNo, fmt::format("expected $VARIABLE[...]=value, CHANDATA(n), a ';' comment or M17; got '{}'", line));
        Assignment a;
        a.line = lineNo;
        size_t i = 1;
        while (i < line.size() && isVariableChar(line[i])) ++i;
        a.variable = std::string(line.substr(0, i));
        if (a.variable.size() < 2) throw InputError(path, lineNo, "missing variable name after '$'");
        if (i < line.size() && line[i] == '[') {
            const size_t close = line.find(']', i);
            if (close == std::string_view::npos) throw InputError(path, lineNo, "missing ']' after the indices");
            a.indices = splitIndices(line.substr(i + 1, close - i - 1));
            for (const auto& idx : a.indices)
                if (idx.empty()) throw InputError(path, lineNo, "empty index");
            i = close + 1;
        }
        if (i >= line.size() || line[i] != '=') throw InputError(path, lineNo, fmt::format("expected '=' after {}", a.variable));
        std::string_view v = trim(line.substr(i + 1));
        // A trailing comment after the value.
        if (!v.empty() && v[0] != '"') {
            const size_t sc = v.find(';');
            if (sc != std::string_view::npos) v = trim(v.substr(0, sc));
        }
        if (v.empty()) throw InputError(path, lineNo, fmt::format("missing value for {}", a.variable));
        if (v.front() == '"') {
            const size_t close = v.find('"', 1);
            if (close == std::string_view::npos) throw InputError(path, lineNo, "unterminated string");
            const std::string_view rest = trim(v.substr(close + 1));
            if (!rest.empty() && rest.front() != ';') throw InputError(path, lineNo, "text after the string value");
            a.value = std::string(v.substr(1, close - 1));
            a.kind = Assignment::Kind::String;
        } else if (v.front() == '(') {
            if (v.back() != ')') throw InputError(path, lineNo, "missing ')' after the axis name");
            a.value = std::string(trim(v.substr(1, v.size() - 2)));
            a.kind = Assignment::Kind::Axis;
        } else {
            if (!parseNumber(v)) throw InputError(path, lineNo, fmt::format("'{}' is not a number", v));
            a.value = std::string(v);
            a.kind = Assignment::Kind::Number;
        }
        f.assignments.push_back(std::move(a));
    }
    if (f.identifier.empty()) throw InputError(path, 1, "empty file: expected the file identifier line");
    if (!ended) throw InputError(path, lineNo, "missing M17 at the end of the file");
    return f;
}

int indexNumber(const AssignmentFile& f, const Assignment& a, size_t which) {
    if (which >= a.indices.size())
        throw InputError(f.path, a.line, fmt::format("{} needs {} indices", a.variable, which + 1));
    const auto n = parseNumber(a.indices[which]);
    if (!n || *n < 0 || *n != std::floor(*n) || *n > 1e6)
        throw InputError(f.path, a.line, fmt::format("index '{}' of {} is not a whole number >= 0", a.indices[which], a.variable));
    return static_cast<int>(*n);
}

double numberValue(const AssignmentFile& f, const Assignment& a) {
    if (a.kind != Assignment::Kind::Number) throw InputError(f.path, a.line, fmt::format("{} needs a number", a.variable));
    const auto v = parseNumber(a.value);
    if (!v || !std::isfinite(*v)) throw InputError(f.path, a.line, fmt::format("{} needs a finite number", a.variable));
    return *v;
}

int axisNumber(const AssignmentFile& f, const Assignment& a, std::string_view text) {
    const std::string_view t = trim(text);
    if (t.size() >= 3 && t.substr(0, 2) == "AX") {
        const auto n = parseNumber(t.substr(2));
        if (n && *n >= 1 && *n == std::floor(*n) && *n < 100) return static_cast<int>(*n);
    }
    throw InputError(f.path, a.line, fmt::format("'{}' is not a machine axis name AXn", t));
}

}  // namespace cnccomp::controllers::siemens
