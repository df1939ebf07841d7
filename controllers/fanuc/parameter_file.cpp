#include "controllers/fanuc/parameter_file.hpp"

#include <cctype>
#include <cmath>
#include <set>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/text_util.hpp"
#include "controllers/common/controller_model.hpp"

namespace cnccomp::controllers::fanuc {
using namespace cnccomp::controllers::common;
using namespace cnccomp::io;

const Parameter* ParameterFile::find(int number, int q) const {
    for (const Parameter& p : parameters)
        if (p.number == number && p.q == q) return &p;
    return nullptr;
}

std::string decimal(double v, int decimals) { return fixed(v, decimals); }

std::string formatParameter(const Parameter& p) {
    std::string s = fmt::format("N{:05d}Q{}", p.number, p.q);
    for (const auto& [index, v] : p.values) {
        if (p.kind == 'P') s += "P" + v;
        else s += fmt::format("{}{}P{}", p.kind, index, v);
    }
    return s;
}

std::string formatParameterFile(const std::string& header, const std::vector<Parameter>& parameters) {
    std::string s = header;
    s += "%\n";
    for (const Parameter& p : parameters) s += formatParameter(p) + "\n";
    s += "%\n";
    return s;
}

namespace {

bool isDigit(char c) { return std::isdigit(static_cast<unsigned char>(c)) != 0; }

/// Reads digits at `i`; returns the text, advancing `i`.
std::string digits(std::string_view l, size_t& i) {
    const size_t s = i;
    while (i < l.size() && isDigit(l[i])) ++i;
    return std::string(l.substr(s, i - s));
}

/// A P value: [+-]digits[.digits].
std::string number(std::string_view l, size_t& i) {
    const size_t s = i;
    if (i < l.size() && (l[i] == '+' || l[i] == '-')) ++i;
    const size_t d = i;
    while (i < l.size() && isDigit(l[i])) ++i;
    if (i == d) return {};
    if (i < l.size() && l[i] == '.') {
        ++i;
        const size_t f = i;
        while (i < l.size() && isDigit(l[i])) ++i;
        if (i == f) return {};
    }
    return std::string(l.substr(s, i - s));
}

}  // namespace

ParameterFile parseParameterFile(const std::string& path, std::string_view text) {
    ParameterFile f;
    f.path = path;
    enum { Leader, Body, Done } state = Leader;
    std::set<std::pair<int, int>> seen;
    int lineNo = 0;
    for (size_t pos = 0; pos < text.size();) {
        const size_t eol = text.find('\n', pos);
        std::string_view l = text.substr(pos, eol == std::string_view::npos ? text.size() - pos : eol - pos);
        pos = eol == std::string_view::npos ? text.size() : eol + 1;
        ++lineNo;
        if (!l.empty() && l.back() == '\r') l.remove_suffix(1);
        for (char c : l)
            if (static_cast<unsigned char>(c) < 0x20 && c != '\t')
                throw InputError(path, lineNo, "binary content: not a Fanuc parameter file");
        const std::string_view t = trim(l);
        if (state == Leader) {
            if (t == "%") state = Body;
            else if (!t.empty() && !(t.front() == '(' && t.back() == ')'))
                throw InputError(path, lineNo, "before the opening % only (comment) lines are allowed");
            continue;
        }
        if (state == Done) {
            if (!t.empty()) throw InputError(path, lineNo, "text after the closing %");
            continue;
        }
        if (l == "%") {
            state = Done;
            f.closingLine = lineNo;
            continue;
        }
        const auto fail = [&](const std::string& why) {
            throw InputError(path, lineNo, fmt::format("'{}' does not match N<5 digits>Q<0|1>(P<v>|L<n>P<v>|(A<n>P<v>)+): {}", l, why));
        };
        Parameter p;
        p.line = lineNo;
        size_t i = 0;
        if (i >= l.size() || l[i] != 'N') fail("expected N");
        ++i;
        const std::string n = digits(l, i);
        if (n.size() != 5) fail("the parameter number has 5 digits");
        p.number = std::stoi(n);
        if (i >= l.size() || l[i] != 'Q') fail("expected Q after the number");
        ++i;
        const std::string q = digits(l, i);
        if (q != "0" && q != "1") fail("Q is 0 or 1");
        p.q = q[0] - '0';
        if (i >= l.size()) fail("missing value");
        if (l[i] == 'P') {
            ++i;
            p.kind = 'P';
            const std::string v = number(l, i);
            if (v.empty()) fail("P needs a number");
            p.values[0] = v;
        } else if (l[i] == 'L' || l[i] == 'A') {
            p.kind = l[i];
            while (i < l.size()) {
                if (l[i] != p.kind) fail(fmt::format("expected {}", p.kind));
                ++i;
                const std::string idx = digits(l, i);
                if (idx.empty() || std::stoi(idx) < 1) fail(fmt::format("{} needs a number >= 1", p.kind));
                if (i >= l.size() || l[i] != 'P') fail("expected P");
                ++i;
                const std::string v = number(l, i);
                if (v.empty()) fail("P needs a number");
                if (!p.values.emplace(std::stoi(idx), v).second) fail(fmt::format("{}{} given twice", p.kind, idx));
                if (p.kind == 'L' && i < l.size()) fail("one path value per line");
            }
        } else {
            fail("expected P, L or A");
        }
        if (p.q == 0 && (p.kind != 'P' || p.number < 10000)) fail("pitch error data are N1nnnnQ0P<value>");
        if (!seen.insert({p.number, p.q}).second) throw InputError(path, lineNo, fmt::format("parameter {} given twice", p.number));
        f.parameters.push_back(std::move(p));
    }
    if (state == Leader) throw InputError(path, lineNo, "missing the opening %");
    if (state == Body) throw InputError(path, lineNo, "missing the closing %");
    return f;
}

double value(const ParameterFile& f, int number, int index, double fallback, int q) {
    const Parameter* p = f.find(number, q);
    if (!p) return fallback;
    const auto it = p->values.find(index);
    if (it == p->values.end()) return fallback;
    const auto v = parseNumber(it->second);
    if (!v || !std::isfinite(*v)) throw InputError(f.path, p->line, fmt::format("parameter {}: '{}' is not a number", number, it->second));
    return *v;
}

double required(const ParameterFile& f, int number, int index, int q) {
    const Parameter* p = f.find(number, q);
    if (!p)
        throw InputError(f.path, f.closingLine,
                         index == 0 ? fmt::format("parameter {} is missing: expected N{:05d}Q{}P<value> before the closing %",
                                                  number, number, q)
                                    : fmt::format("parameter {} is missing: expected a line N{:05d}Q{}(L|A){}P<value> before "
                                                  "the closing %",
                                                  number, number, q, index));
    if (!p->values.count(index))
        throw InputError(f.path, p->line, fmt::format("parameter {} has no value for {}{}", number, p->kind == 'A' ? "axis " : "path ", index));
    return value(f, number, index, 0.0, q);
}

}  // namespace cnccomp::controllers::fanuc
