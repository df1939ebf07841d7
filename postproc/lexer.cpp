#include "postproc/lexer.hpp"

#include "cnccomp/io/number_format.hpp"
#include "cnccomp/io/text_util.hpp"

#include <charconv>
#include <cmath>
#include <string>

namespace cnccomp::postproc {
using namespace cnccomp::io;

const char* lexFlagReason(uint32_t flags) {
    if (flags & kOverlong) return "line longer than the reader's buffer";
    if (flags & kBinary) return "binary (control or non-ASCII) bytes outside comments";
    if (flags & kUnterminatedComment) return "unterminated comment";
    if (flags & kTooManyWords) return "too many words in one block";
    if (flags & kAssignment) return "parameter assignment";
    if (flags & kExpression) return "expression";
    if (flags & kVariable) return "variable";
    if (flags & kCall) return "subprogram or cycle call";
    if (flags & kIdentifier) return "keyword";
    if (flags & kMissingValue) return "address letter without a number";
    if (flags & kExponent) return "number in exponent notation (e.g. 1e-3), which G-code does not have";
    if (flags & kBadNumber) return "malformed or out-of-range number";
    if (flags & kUnknownChar) return "unexpected character";
    return "";
}

namespace {


inline bool isDigit(unsigned char c) { return c >= '0' && c <= '9'; }
inline bool isAlpha(unsigned char c) { return (c | 0x20) >= 'a' && (c | 0x20) <= 'z'; }
inline bool isSpace(unsigned char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }
inline char upper(unsigned char c) { return static_cast<char>(c & ~0x20); }

/// Scans a number at s[i]; fills w's number fields. Returns the end offset, or i when there is no number.
size_t scanNumber(std::string_view s, size_t i, Word& w, bool& bad) {
    const size_t n = s.size(), start = i;
    bool neg = false;
    if (i < n && (s[i] == '+' || s[i] == '-')) {
        neg = s[i] == '-';
        w.plus = s[i] == '+';
        ++i;
    }
    uint64_t mantissa = 0;
    int digits = 0, before = 0, after = 0;
    while (i < n && isDigit(s[i])) {
        if (digits < 19) mantissa = mantissa * 10 + static_cast<unsigned>(s[i] - '0');
        ++digits;
        ++before;
        ++i;
    }
    if (i < n && s[i] == '.') {
        w.point = true;
        ++i;
        while (i < n && isDigit(s[i])) {
            if (digits < 19) mantissa = mantissa * 10 + static_cast<unsigned>(s[i] - '0');
            ++digits;
            ++after;
            ++i;
        }
    }
    if (digits == 0) {
        w.plus = false;
        w.point = false;
        return start;
    }
    w.bareFraction = before == 0;
    w.digitsBefore = static_cast<uint8_t>(before > 255 ? 255 : before);
    w.decimals = static_cast<uint8_t>(after > 255 ? 255 : after);
    w.trailingZero = after > 0 && s[i - 1] == '0';
    if (digits <= 15 && after <= 22) {
        // Exact integer mantissa divided by an exact power of ten: correctly rounded.
        const double v = static_cast<double>(mantissa) / kPow10[after];
        w.value = neg ? -v : v;
    } else {
        double v = 0.0;
        const char* b = s.data() + start + ((s[start] == '+' || s[start] == '-') ? 1 : 0);
        const auto r = std::from_chars(b, s.data() + i, v, std::chars_format::fixed);
        if (r.ec != std::errc() || !std::isfinite(v)) bad = true;
        w.value = neg ? -v : v;
    }
    return i;
}

/// Skips [ … ] with nesting; returns the offset after the closing bracket (or the end of the line).
size_t skipBrackets(std::string_view s, size_t i, uint32_t& flags) {
    int depth = 0;
    for (; i < s.size(); ++i) {
        if (s[i] == '[') ++depth;
        else if (s[i] == ']' && --depth == 0) return i + 1;
    }
    flags |= kExpression;
    return i;
}

/// Skips #123, #<name>, #[expr], ##1.
size_t skipVariable(std::string_view s, size_t i, uint32_t& flags) {
    while (i < s.size() && s[i] == '#') ++i;
    if (i < s.size() && s[i] == '<') {
        const size_t close = s.find('>', i);
        return close == std::string_view::npos ? s.size() : close + 1;
    }
    if (i < s.size() && s[i] == '[') return skipBrackets(s, i, flags);
    while (i < s.size() && (isDigit(s[i]) || isAlpha(s[i]) || s[i] == '_')) ++i;
    return i;
}

void problem(LexedBlock& b, uint32_t flag, size_t at) {
    if ((b.flags & kNotEvaluable) == 0 && (flag & kNotEvaluable)) b.problemAt = static_cast<uint32_t>(at);
    b.flags |= flag;
}

bool printerTextCode(int m) { return m == 23 || m == 28 || m == 30 || m == 32 || m == 117 || m == 118 || m == 928; }

}  // namespace

void OverlongLine::feed(std::string_view piece) {
    for (const char ch : piece) {
        const unsigned char c = static_cast<unsigned char>(ch);
        if (inComment) return;
        if (inParen) {
            if (c == ')') inParen = false;
            continue;
        }
        if (c == '(') {
            inParen = true;
            lastWasLetter = false;
            continue;
        }
        if (c == ';') {
            inComment = true;
            return;
        }
        if (isSpace(c)) continue;
        code = true;
        if (isAlpha(c)) {
            // A letter right after a letter is a keyword (GOTO, TRAORI …): not a plain word.
            if (lastWasLetter) other = true;
            letters |= 1u << (upper(c) - 'A');
            lastWasLetter = true;
            continue;
        }
        lastWasLetter = false;
        if (!(isDigit(c) || c == '.' || c == '-' || c == '+' || c == '/')) other = true;
    }
}

bool parseGcodeNumber(std::string_view text, double& value) {
    Word w;
    bool bad = false;
    const size_t end = scanNumber(text, 0, w, bad);
    if (end == 0 || end != text.size() || bad) return false;
    value = w.value;
    return true;
}

void lexBlock(std::string_view s, Dialect dialect, LexedBlock& b, bool firstLine) {
    b.count = 0;
    b.identifierCount = 0;
    b.flags = 0;
    b.problemAt = 0;
    b.blockDelete = -1;
    b.codeEnd = 0;
    b.percent = false;
    b.spaced = false;
    b.lowerCase = false;
    b.hasComment = false;
    const size_t n = s.size();
    size_t i = 0;
    if (firstLine) i = n - withoutByteOrderMark(s).size();
    while (i < n && isSpace(s[i])) ++i;
    if (i < n && s[i] == '%') {
        b.percent = true;
        return;
    }
    if (i < n && s[i] == '/') {
        b.blockDelete = static_cast<int>(i);
        ++i;
        while (i < n && isDigit(s[i])) ++i;  // block-delete level (/1 … /9)
    }
    bool sawSpace = false;
    bool afterToken = false;
    auto endToken = [&](size_t at) {
        b.codeEnd = static_cast<uint32_t>(at);
        afterToken = true;
        sawSpace = false;
    };
    while (i < n) {
        const unsigned char c = static_cast<unsigned char>(s[i]);
        if (isSpace(c)) {
            sawSpace = true;
            ++i;
            continue;
        }
        if (c == '(' ) {
            b.hasComment = true;
            const size_t close = s.find(')', i + 1);
            if (close == std::string_view::npos) {
                problem(b, kUnterminatedComment, i);
                return;
            }
            i = close + 1;
            continue;
        }
        if (c == ';') {
            b.hasComment = true;
            return;
        }
        if (isAlpha(c)) {
            if (afterToken && sawSpace) b.spaced = true;
            const size_t begin = i;
            // Multi-letter keyword: a letter followed directly by a letter or an underscore.
            if (i + 1 < n && (isAlpha(s[i + 1]) || s[i + 1] == '_')) {
                size_t j = i;
                while (j < n && (isAlpha(s[j]) || isDigit(s[j]) || s[j] == '_')) ++j;
                if (b.identifierCount < LexedBlock::kMaxIdentifiers)
                    b.identifiers[b.identifierCount++] = {static_cast<uint32_t>(begin), static_cast<uint32_t>(j)};
                size_t k = j;
                while (k < n && isSpace(s[k])) ++k;
                if (dialect == Dialect::Sinumerik && k < n && s[k] == '(') {
                    // NAME(arguments): skip to the matching parenthesis, quotes respected.
                    int depth = 0;
                    bool quoted = false;
                    for (; k < n; ++k) {
                        if (s[k] == '"') quoted = !quoted;
                        if (quoted) continue;
                        if (s[k] == '(') ++depth;
                        else if (s[k] == ')' && --depth == 0) break;
                    }
                    j = k < n ? k + 1 : n;
                    problem(b, kCall, begin);
                } else {
                    problem(b, kIdentifier, begin);
                }
                i = j;
                endToken(i);
                continue;
            }
            if (b.count >= LexedBlock::kMaxWords) {
                problem(b, kTooManyWords, begin);
                return;
            }
            Word& w = b.words[b.count];
            w = Word{};
            w.begin = static_cast<uint32_t>(begin);
            w.letter = upper(c);
            w.lower = c >= 'a';
            b.lowerCase = w.lower;
            size_t j = i + 1;
            while (j < n && (s[j] == ' ' || s[j] == '\t')) ++j;  // RS274NGC allows "X 1.5"
            w.valueBegin = static_cast<uint32_t>(j);
            if (j < n && s[j] == '[') {
                w.kind = ValueKind::Expression;
                problem(b, kExpression, j);
                j = skipBrackets(s, j, b.flags);
            } else if (j < n && (s[j] == '#' || s[j] == '$' ||
                                 ((s[j] == '-' || s[j] == '+') && j + 1 < n && (s[j + 1] == '#' || s[j + 1] == '[')))) {
                w.kind = ValueKind::Variable;
                problem(b, kVariable, j);
                if (s[j] == '-' || s[j] == '+') ++j;
                if (s[j] == '[') j = skipBrackets(s, j, b.flags);
                else if (s[j] == '$') {
                    ++j;
                    while (j < n && (isAlpha(s[j]) || isDigit(s[j]) || s[j] == '_')) ++j;
                } else j = skipVariable(s, j, b.flags);
            } else if (j < n && s[j] == '=') {
                w.kind = ValueKind::Assignment;
                problem(b, kAssignment, j);
                w.end = static_cast<uint32_t>(n);
                ++b.count;
                b.codeEnd = static_cast<uint32_t>(n);
                return;  // the rest of the block is the assigned expression
            } else {
                bool bad = false;
                const size_t e = scanNumber(s, j, w, bad);
                if (e == j) {
                    w.kind = ValueKind::Missing;
                    w.valueBegin = static_cast<uint32_t>(i + 1);
                    problem(b, kMissingValue, begin);
                    j = i + 1;
                } else {
                    if (bad) problem(b, kBadNumber, j);
                    j = e;
                    // "X1e-3": RS274NGC (LinuxCNC reads an E word and stops: "E word with no G70, G76, M66, M67 or
                    // M68 to use it", interp_check.cc), Fanuc and Sinumerik (1EX-3) have no such notation: never read
                    // it as X1 silently. Printers (Marlin) end the number at 'E' and read an extruder word [G].
                    if (dialect != Dialect::Printer && j < n && (s[j] == 'e' || s[j] == 'E')) {
                        size_t k = j + 1;
                        if (k < n && (s[k] == '+' || s[k] == '-')) ++k;
                        if (k < n && isDigit(static_cast<unsigned char>(s[k]))) {
                            problem(b, kExponent, j);
                            w.kind = ValueKind::Exponent;  // its value is not the number's: never used
                        }
                    }
                    // A number directly followed by '=' is an assignment target (R1=…, #1=…), or on Sinumerik an
                    // address with an extension and a plain number: A3=0.5 (orientation vector component).
                    size_t k = j;
                    while (k < n && isSpace(s[k])) ++k;
                    if (k < n && s[k] == '=' && dialect == Dialect::Sinumerik && !w.point && !w.plus &&
                        (w.letter == 'A' || w.letter == 'B' || w.letter == 'C') &&
                        s[w.valueBegin] != '-' && w.value >= 1 && w.value <= 9 && w.valueBegin == i + 1) {
                        size_t m = k + 1;
                        while (m < n && (s[m] == ' ' || s[m] == '\t')) ++m;
                        Word v;
                        bool badValue = false;
                        const size_t e2 = scanNumber(s, m, v, badValue);
                        const bool ends = e2 >= n || isSpace(s[e2]) || s[e2] == ';' || s[e2] == '(';
                        if (e2 > m && !badValue && ends) {
                            const auto ext = static_cast<uint8_t>(w.value);
                            const uint32_t wordBegin = w.begin;
                            const bool wasLower = w.lower;
                            w = v;
                            w.begin = wordBegin;
                            w.letter = upper(c);
                            w.lower = wasLower;
                            w.ext = ext;
                            w.valueBegin = static_cast<uint32_t>(m);
                            w.end = static_cast<uint32_t>(e2);
                            ++b.count;
                            i = e2;
                            endToken(i);
                            continue;
                        }
                    }
                    if (k < n && s[k] == '=') {
                        w.end = static_cast<uint32_t>(n);
                        ++b.count;
                        problem(b, kAssignment, k);
                        b.codeEnd = static_cast<uint32_t>(n);
                        return;
                    }
                }
            }
            w.end = static_cast<uint32_t>(j);
            ++b.count;
            i = j;
            endToken(i);
            if (dialect == Dialect::Printer && w.letter == 'M' && w.kind == ValueKind::Number && w.value >= 0 &&
                w.value < 1000 && w.value == std::floor(w.value) && printerTextCode(static_cast<int>(w.value))) {
                // M117 Hello: the rest of the block (up to a ';' comment) is text.
                const size_t semi = s.find(';', i);
                const size_t stop = semi == std::string_view::npos ? n : semi;
                size_t last = stop;
                while (last > i && isSpace(s[last - 1])) --last;
                if (last > i) {
                    b.flags |= kTextArgument;
                    b.codeEnd = static_cast<uint32_t>(last);
                }
                if (semi != std::string_view::npos) b.hasComment = true;
                return;
            }
            continue;
        }
        if (c == '#') {
            // #100 = … (macro assignment) or a bare variable.
            const size_t begin = i;
            i = skipVariable(s, i, b.flags);
            size_t k = i;
            while (k < n && isSpace(s[k])) ++k;
            if (k < n && s[k] == '=') {
                problem(b, kAssignment, begin);
                b.codeEnd = static_cast<uint32_t>(n);
                return;
            }
            problem(b, kVariable, begin);
            endToken(i);
            continue;
        }
        if (c == '$') {
            const size_t begin = i++;
            while (i < n && (isAlpha(s[i]) || isDigit(s[i]) || s[i] == '_')) ++i;
            problem(b, kVariable, begin);
            endToken(i);
            continue;
        }
        if (c == '[') {
            const size_t begin = i;
            i = skipBrackets(s, i, b.flags);
            problem(b, kExpression, begin);
            endToken(i);
            continue;
        }
        if (c == '=') {
            problem(b, kAssignment, i);
            b.codeEnd = static_cast<uint32_t>(n);
            return;
        }
        if (c >= 0x80 || c < 0x20 || c == 0x7f) {
            problem(b, kBinary, i);
            ++i;
            continue;
        }
        problem(b, kUnknownChar, i);
        ++i;
        endToken(i);
    }
}

}  // namespace cnccomp::postproc
