#include "postproc/dialect.hpp"

#include <array>
#include <cctype>
#include <string>

namespace cnccomp::postproc {

namespace {

/// The one name table. `uses`: where the name is accepted; `listed`: where it is the dialect's own name (messages,
/// summaries). Test programs name RS274NGC after LinuxCNC, for which they are written.
struct DialectNameRow {
    std::string_view name;
    Dialect dialect;
    unsigned uses, listed;
};
constexpr unsigned kRead = 1, kCorrect = 2, kWrite = 4, kAll = kRead | kCorrect | kWrite;
constexpr DialectNameRow kDialectNames[] = {
    {"rs274ngc", Dialect::Rs274ngc, kAll, kRead | kCorrect},
    {"linuxcnc", Dialect::Rs274ngc, kAll, kWrite},
    {"rs274", Dialect::Rs274ngc, kRead | kCorrect, 0},
    {"ngc", Dialect::Rs274ngc, kAll, 0},
    {"fanuc", Dialect::Fanuc, kAll, kAll},
    {"haas", Dialect::Fanuc, kRead | kCorrect, 0},
    {"sinumerik", Dialect::Sinumerik, kAll, kAll},
    {"siemens", Dialect::Sinumerik, kAll, 0},
    {"printer", Dialect::Printer, kRead | kCorrect, kRead | kCorrect},
    {"marlin", Dialect::Printer, kRead | kCorrect, 0},
    {"reprap", Dialect::Printer, kRead | kCorrect, 0},
    {"3d-printer", Dialect::Printer, kRead | kCorrect, 0},
    {"heidenhain", Dialect::Heidenhain, kCorrect | kWrite, kAll},
    {"klartext", Dialect::Heidenhain, kCorrect | kWrite, 0},
    {"tnc", Dialect::Heidenhain, kWrite, 0},
};

}  // namespace

std::optional<Dialect> parseDialect(std::string_view name, DialectUse use) {
    std::string n;
    for (char c : name) n.push_back(static_cast<char>(std::tolower(static_cast<unsigned char>(c))));
    for (const DialectNameRow& row : kDialectNames)
        if ((row.uses & static_cast<unsigned>(use)) && row.name == n) return row.dialect;
    return std::nullopt;
}

const char* dialectName(Dialect d, DialectUse use) {
    for (const DialectNameRow& row : kDialectNames)
        if (row.dialect == d && (row.listed & static_cast<unsigned>(use))) return row.name.data();
    for (const DialectNameRow& row : kDialectNames)
        if (row.dialect == d && row.listed) return row.name.data();
    return "?";
}

std::string dialectNames(DialectUse use) {
    std::string out;
    for (const DialectNameRow& row : kDialectNames)
        if ((row.uses & static_cast<unsigned>(use)) && (row.listed & static_cast<unsigned>(use))) {
            if (!out.empty()) out += ", ";
            out += row.name;
        }
    return out;
}

namespace {

bool startsWith(std::string_view s, std::string_view p) { return s.substr(0, p.size()) == p; }
bool contains(std::string_view s, std::string_view p) { return s.find(p) != std::string_view::npos; }

/// Upper-cased copy of a line without its comments in parentheses (clues inside comments do not count).
std::string codeOf(std::string_view line) {
    std::string out;
    bool inParen = false;
    for (char c : line) {
        if (inParen) {
            if (c == ')') inParen = false;
            continue;
        }
        if (c == '(') {
            inParen = true;
            continue;
        }
        out.push_back(static_cast<char>(std::toupper(static_cast<unsigned char>(c))));
    }
    return out;
}

/// "0 BEGIN PGM NAME MM": a HEIDENHAIN Klartext program decides alone (its blocks would look like ISO words).
bool isKlartextHeader(std::string_view line) {
    size_t i = 0;
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || std::isdigit(static_cast<unsigned char>(line[i])))) ++i;
    return startsWith(line.substr(i), "BEGIN PGM ");
}

/// A G0/G1 block with an E word: extruder moves of a printer. The E must stand after a blank (slicers write
/// "G1 X10 E0.5") or right after the G0/G1 code ("G1E5"): an E right after the digits of another word is a number
/// in exponent notation ("G1 X1e1"), which a milling program may hold by mistake and which the lexer refuses by line
/// in the milling dialects (kExponent) — one such word must not turn a whole program into printer code.
bool hasExtruderWord(std::string_view code) {
    if (!(startsWith(code, "G1") || startsWith(code, "G0"))) return false;
    for (size_t i = 1; i + 1 < code.size(); ++i)
        if (code[i] == 'E' && (code[i - 1] == ' ' || code[i - 1] == '\t' || i == 2) &&
            (std::isdigit(static_cast<unsigned char>(code[i + 1])) || code[i + 1] == '-' || code[i + 1] == '.'))
            return true;
    return false;
}

}  // namespace

int klartextHeaderLine(std::string_view head) {
    for (int line = 1; !head.empty() && line <= 2000; ++line) {
        const size_t eol = head.find_first_of("\r\n");
        if (isKlartextHeader(head.substr(0, eol))) return line;
        if (eol == std::string_view::npos) break;
        head.remove_prefix(eol + (head[eol] == '\r' && eol + 1 < head.size() && head[eol + 1] == '\n' ? 2 : 1));
    }
    return 0;
}

DetectedDialect detectDialect(std::string_view head) {
    enum { kNgc, kFanuc, kSiemens, kPrinter, kFamilies };
    std::array<int, kFamilies> score{};
    std::array<const char*, kFamilies> why{"", "", "", ""};
    auto clue = [&](int family, const char* reason) {
        if (score[family]++ == 0) why[family] = reason;
    };
    int lines = 0;
    while (!head.empty() && lines < 2000) {
        const size_t eol = head.find('\n');
        std::string_view raw = head.substr(0, eol);
        head = eol == std::string_view::npos ? std::string_view{} : head.substr(eol + 1);
        ++lines;
        if (startsWith(raw, ";FLAVOR:") || startsWith(raw, ";Generated with Cura") || startsWith(raw, "; generated by PrusaSlicer") ||
            startsWith(raw, "; generated by Slic3r"))
            clue(kPrinter, "slicer header comment");
        if (isKlartextHeader(raw)) return {Dialect::Heidenhain, true, "BEGIN PGM program header"};
        const size_t semi = raw.find(';');
        const std::string code = codeOf(raw.substr(0, semi));
        std::string_view c = code;
        while (!c.empty() && (c.front() == ' ' || c.front() == '\t')) c.remove_prefix(1);
        if (c.empty()) continue;
        if (startsWith(c, "%_N_") || contains(c, "_MPF") || contains(c, "_SPF")) clue(kSiemens, "%_N_ program header");
        if (contains(c, "TRAORI") || contains(c, "TRAFOOF") || contains(c, "CYCLE8") || contains(c, "G291") ||
            contains(c, "MSG(") || contains(c, "SUPA") || contains(c, "$P_") || contains(c, "$AA_") || contains(c, "DIAMON"))
            clue(kSiemens, "Sinumerik keyword");
        if ((c.front() == 'O' || c.front() == ':') && c.size() > 1 && std::isdigit(static_cast<unsigned char>(c[1])))
            clue(kFanuc, "O-number program header");
        if (contains(c, "G65") || contains(c, "M98") || contains(c, "G43.4") || contains(c, "G43.5") ||
            contains(c, "G68.2") || contains(c, "G53.1"))
            clue(kFanuc, "Fanuc macro call or TCP code");
        // #100 numbered variables exist in Fanuc macros and in RS274NGC alike: no clue.
        if (contains(c, "#<") || (c.front() == 'O' && c.size() > 1 && c[1] == '<') || contains(c, " SUB") ||
            contains(c, "ENDSUB") || contains(c, "G43.1") || contains(c, "G64 P"))
            clue(kNgc, "RS274NGC named parameter or o-word");
        if (startsWith(c, "M104") || startsWith(c, "M109") || startsWith(c, "M140") || startsWith(c, "M190") ||
            startsWith(c, "M82") || startsWith(c, "M83") || hasExtruderWord(c))
            clue(kPrinter, "extruder or heater codes");
    }
    int families = 0, best = kNgc;
    for (int f = 0; f < kFamilies; ++f)
        if (score[f] > 0) {
            ++families;
            if (score[best] == 0 || score[f] > score[best]) best = f;
        }
    static constexpr Dialect kOf[kFamilies] = {Dialect::Rs274ngc, Dialect::Fanuc, Dialect::Sinumerik, Dialect::Printer};
    if (families == 1) return {kOf[best], true, why[best]};
    if (families == 0) return {Dialect::Rs274ngc, false, "no dialect-specific code found"};
    return {Dialect::Rs274ngc, false, "clues of several dialects"};
}

}  // namespace cnccomp::postproc
