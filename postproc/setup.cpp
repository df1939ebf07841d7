#include "postproc/setup.hpp"

#include <cctype>
#include <cmath>
#include <fstream>
#include <optional>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/text_util.hpp"

namespace cnccomp::postproc {
using namespace cnccomp::io;

int offsetCodeOfG(double g, int p) {
    const int code = static_cast<int>(std::lround(g * 10));
    if (code == 541) return 100000 + p;
    return code;
}

std::optional<int> parseOffsetCode(std::string_view name) {
    std::string s;
    for (char c : name)
        if (c != ' ') s.push_back(static_cast<char>(std::toupper(static_cast<unsigned char>(c))));
    if (s.size() < 2 || s[0] != 'G') return std::nullopt;
    std::string_view rest = std::string_view(s).substr(1);
    int p = 0;
    const size_t pp = rest.find('P');
    if (pp != std::string_view::npos) {
        const auto pv = parseNumber(rest.substr(pp + 1));
        if (!pv || *pv < 1 || *pv > 300 || *pv != std::floor(*pv)) return std::nullopt;
        p = static_cast<int>(*pv);
        rest = rest.substr(0, pp);
    }
    const auto g = parseNumber(rest);
    if (!g) return std::nullopt;
    const int code = static_cast<int>(std::lround(*g * 10));
    if (std::fabs(*g * 10 - code) > 1e-6) return std::nullopt;
    if (code == 541) return p > 0 ? std::optional<int>(100000 + p) : std::nullopt;
    if (p != 0) return std::nullopt;
    const bool iso = code == 540 || code == 550 || code == 560 || code == 570 || code == 580 || code == 590 ||
                     code == 591 || code == 592 || code == 593;
    const bool siemens = code == 5000 || (code >= 5050 && code <= 5990 && code % 10 == 0);
    if (iso || siemens) return code;
    return std::nullopt;
}

std::string offsetCodeName(int code) {
    if (code >= 100000) return fmt::format("G54.1 P{}", code - 100000);
    if (code % 10 == 0) return fmt::format("G{}", code / 10);
    return fmt::format("G{}.{}", code / 10, code % 10);
}

std::optional<int> parseMCode(std::string_view text) {
    text = trim(text);
    if (!text.empty() && (text[0] == 'M' || text[0] == 'm')) text.remove_prefix(1);
    const auto v = parseNumber(text);
    if (!v || *v < 0 || *v > 99999 || *v != std::floor(*v)) return std::nullopt;
    return static_cast<int>(*v);
}

const WorkOffset* Setup::offset(int code) const {
    for (const WorkOffset& w : offsets)
        if (w.code == code) return &w;
    return nullptr;
}

std::optional<double> Setup::toolLength(int number) const {
    for (const auto& [n, l] : toolLengths)
        if (n == number) return l;
    return std::nullopt;
}

void Setup::addWorkOffset(std::string_view spec, const std::string& source, int line) {
    const size_t eq = spec.find('=');
    if (eq == std::string_view::npos)
        throw InputError(source, line, fmt::format("expected CODE=x,y,z[,a,b,c] (e.g. G54=100,0,-300), got '{}'", spec));
    const auto code = parseOffsetCode(trim(spec.substr(0, eq)));
    if (!code)
        throw InputError(source, line,
                         fmt::format("'{}' is not a work offset (G54…G59, G59.1…G59.3, G54.1 Pn, G500, G505…G599)",
                                     trim(spec.substr(0, eq))));
    WorkOffset w;
    w.code = *code;
    std::string_view values = spec.substr(eq + 1);
    int k = 0;
    while (true) {
        const size_t comma = values.find(',');
        const std::string_view cell = trim(values.substr(0, comma));
        if (k >= 6) throw InputError(source, line, "a work offset has at most six values x,y,z,a,b,c");
        const auto v = parseNumber(cell);
        if (!v || !std::isfinite(*v))
            throw InputError(source, line, fmt::format("work offset value {} '{}' is not a finite number", k + 1, cell));
        w.xyzabc[k++] = *v;
        if (comma == std::string_view::npos) break;
        values = values.substr(comma + 1);
    }
    if (k < 3) throw InputError(source, line, "a work offset needs at least x,y,z (mm)");
    for (WorkOffset& o : offsets)
        if (o.code == w.code) {
            o = w;
            return;
        }
    offsets.push_back(w);
}

void Setup::addToolLength(std::string_view spec, const std::string& source, int line) {
    spec = trim(spec);
    const size_t eq = spec.find('=');
    const std::string_view valueText = eq == std::string_view::npos ? spec : trim(spec.substr(eq + 1));
    const auto v = parseNumber(valueText);
    if (!v || !std::isfinite(*v) || std::fabs(*v) > 1e5)
        throw InputError(source, line, fmt::format("tool length '{}' is not a finite number of mm", valueText));
    if (eq == std::string_view::npos) {
        defaultToolLength = *v;
        defaultToolLengthGiven = true;
        return;
    }
    std::string_view key = trim(spec.substr(0, eq));
    if (!key.empty() && (key[0] == 'H' || key[0] == 'h' || key[0] == 'T' || key[0] == 't' || key[0] == 'D' || key[0] == 'd'))
        key.remove_prefix(1);
    const auto n = parseNumber(key);
    if (!n || *n < 0 || *n > 100000 || *n != std::floor(*n))
        throw InputError(source, line, fmt::format("expected Hn=length (e.g. H3=120.5), got '{}'", spec));
    for (auto& [num, len] : toolLengths)
        if (num == static_cast<int>(*n)) {
            len = *v;
            return;
        }
    toolLengths.emplace_back(static_cast<int>(*n), *v);
}

void Setup::addAssumed(std::string_view spec, const std::string& source, int line) {
    while (!spec.empty()) {
        const size_t comma = spec.find(',');
        const std::string_view item = trim(spec.substr(0, comma));
        spec = comma == std::string_view::npos ? std::string_view{} : spec.substr(comma + 1);
        const size_t eq = item.find('=');
        const std::string_view name = eq == std::string_view::npos ? item : trim(item.substr(0, eq));
        if (eq == std::string_view::npos || name.size() != 1 || !std::isalpha(static_cast<unsigned char>(name[0])))
            throw InputError(source, line, fmt::format("expected AXIS=value (e.g. Y=0), got '{}'", item));
        const auto v = parseNumber(item.substr(eq + 1));
        if (!v || !std::isfinite(*v) || std::fabs(*v) > 1e6)
            throw InputError(source, line, fmt::format("'{}': the position is not a finite number", item));
        const char letter = static_cast<char>(std::toupper(static_cast<unsigned char>(name[0])));
        bool replaced = false;
        for (auto& [l, value] : assumed)
            if (l == letter) value = *v, replaced = true;
        if (!replaced) assumed.emplace_back(letter, *v);
    }
}

void Setup::readFile(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(path, 0, "cannot open the setup file");
    std::string text;
    int lineNo = 0;
    while (std::getline(in, text)) {
        ++lineNo;
        std::string_view l = trim(lineNo == 1 ? withoutByteOrderMark(text) : std::string_view(text));
        const size_t hash = l.find('#');
        if (hash != std::string_view::npos) l = trim(l.substr(0, hash));
        if (l.empty()) continue;
        const size_t sp = l.find_first_of(" \t");
        const std::string_view key = l.substr(0, sp);
        const std::string_view value = sp == std::string_view::npos ? std::string_view{} : trim(l.substr(sp));
        if (key == "work-offset") addWorkOffset(value, path, lineNo);
        else if (key == "tool-length") addToolLength(value, path, lineNo);
        else if (key == "assume") addAssumed(value, path, lineNo);
        else if (key == "units") {
            if (value == "inch") inchDefault = true;
            else if (value == "mm") inchDefault = false;
            else throw InputError(path, lineNo, fmt::format("units must be 'mm' or 'inch', got '{}'", value));
        } else
            throw InputError(path, lineNo,
                             fmt::format("expected 'work-offset G54=x,y,z', 'tool-length [Hn=]L', 'assume Y=0' or 'units mm|inch', got '{}'", key));
    }
}

void Setup::readToolTable(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(path, 0, "cannot open the tool table");
    std::string text;
    int lineNo = 0, tools = 0;
    while (std::getline(in, text)) {
        ++lineNo;
        std::string_view l = lineNo == 1 ? withoutByteOrderMark(text) : std::string_view(text);
        const size_t semi = l.find(';');
        if (semi != std::string_view::npos) l = l.substr(0, semi);
        l = trim(l);
        if (l.empty()) continue;
        int tool = -1;
        std::optional<double> z;
        while (!l.empty()) {
            const size_t sp = l.find_first_of(" \t");
            const std::string_view word = l.substr(0, sp);
            l = sp == std::string_view::npos ? std::string_view{} : trim(l.substr(sp));
            const char letter = static_cast<char>(std::toupper(static_cast<unsigned char>(word[0])));
            const auto v = parseNumber(word.substr(1));
            if (std::string_view("TPXYZABCUVWDIJQ").find(letter) == std::string_view::npos || !v || !std::isfinite(*v))
                throw InputError(path, lineNo,
                                 fmt::format("expected tool table words T P X Y Z A B C U V W D I J Q with numbers "
                                             "(LinuxCNC format, e.g. 'T1 P1 Z12.5 D6 ;comment'), got '{}'",
                                             word));
            if (letter == 'T') {
                if (*v < 0 || *v > 99999 || *v != std::floor(*v))
                    throw InputError(path, lineNo, fmt::format("tool number '{}' is not a whole number", word));
                tool = static_cast<int>(*v);
            }
            if (letter == 'Z') z = *v;
        }
        if (tool < 0) throw InputError(path, lineNo, "a tool table line without a T word");
        addToolLength(fmt::format("T{}={}", tool, z ? *z : 0.0), path, lineNo);
        ++tools;
    }
    if (tools == 0) throw InputError(path, 0, "the tool table lists no tools");
}

}  // namespace cnccomp::postproc
