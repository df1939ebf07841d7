#pragma once
// Hand-written G-code lexer over one block (one line, without its line ending). No allocation: words are
// byte spans into the line plus their parsed value, so that a writer can replace a number and keep every
// other byte. Anything the lexer does not understand is flagged, never guessed: the block then passes
// through unchanged and is reported.
#include <array>
#include <cstdint>
#include <string_view>

#include "postproc/dialect.hpp"

namespace cnccomp::postproc {

/// Why a block cannot be evaluated (bit flags of LexedBlock::flags).
enum LexFlag : uint32_t {
    kUnterminatedComment = 1u << 0,  ///< '(' without ')'
    kExpression = 1u << 1,           ///< [ … ] expression
    kVariable = 1u << 2,             ///< #100, #<name>, $VAR
    kAssignment = 1u << 3,           ///< '=' (macro or R-parameter assignment, Sinumerik X=…)
    kIdentifier = 1u << 4,           ///< multi-letter keyword (GOTO, IF, TRAORI, sub, CYCLE800 …)
    kMissingValue = 1u << 5,         ///< a letter without a number (e.g. "P" alone)
    kBadNumber = 1u << 6,            ///< a number that does not parse or overflows a double
    kBinary = 1u << 7,               ///< control or non-ASCII bytes outside comments
    kUnknownChar = 1u << 8,          ///< a character with no meaning here ('*', '"', ':' …)
    kTooManyWords = 1u << 9,         ///< more than LexedBlock::kMaxWords words
    kCall = 1u << 10,                ///< NAME(arguments) call (Sinumerik)
    kTextArgument = 1u << 11,        ///< M117-style text argument (printer; harmless)
    kOverlong = 1u << 12,            ///< set by the reader: the line was longer than its buffer
    kExponent = 1u << 13,            ///< a number in exponent notation (X1e-3): no G-code dialect reads it so
};

/// Flags that make a block's words impossible to evaluate.
inline constexpr uint32_t kNotEvaluable = kUnterminatedComment | kExpression | kVariable | kAssignment | kIdentifier |
                                          kMissingValue | kBadNumber | kBinary | kUnknownChar | kTooManyWords |
                                          kCall | kOverlong | kExponent;

/// Human-readable reason of the lowest set flag in `flags` (a static string).
const char* lexFlagReason(uint32_t flags);

enum class ValueKind : uint8_t { Number, Missing, Expression, Variable, Assignment, Exponent };

/// One address word: a letter and its value. Offsets are into the block's line.
struct Word {
    uint32_t begin = 0;       ///< offset of the letter
    uint32_t valueBegin = 0;  ///< offset of the number text (sign included)
    uint32_t end = 0;         ///< one past the last byte of the word
    double value = 0.0;       ///< parsed number (ValueKind::Number only)
    char letter = 0;          ///< upper case
    ValueKind kind = ValueKind::Number;
    bool lower = false;         ///< the letter was written in lower case
    bool point = false;         ///< the number has a decimal point
    bool plus = false;          ///< explicit '+' sign
    bool bareFraction = false;  ///< written without a digit before the point (".5", "-.5")
    bool trailingZero = false;  ///< the fraction ends in '0' (fixed-width style)
    uint8_t decimals = 0;       ///< digits after the point
    uint8_t digitsBefore = 0;   ///< digits before the point (leading zeros included)
    uint8_t ext = 0;            ///< Sinumerik address extension: A3=0.5 is letter A, ext 3 (0: a plain word)
};

struct Span {
    uint32_t begin = 0, end = 0;
};

struct LexedBlock {
    static constexpr int kMaxWords = 64;
    static constexpr int kMaxIdentifiers = 4;
    std::array<Word, kMaxWords> words;
    int count = 0;
    std::array<Span, kMaxIdentifiers> identifiers;  ///< multi-letter keywords (first few)
    int identifierCount = 0;
    uint32_t flags = 0;
    uint32_t problemAt = 0;     ///< offset of the first problem (when flags has a kNotEvaluable bit)
    int blockDelete = -1;       ///< offset of a leading '/', or -1
    uint32_t codeEnd = 0;       ///< one past the last word / keyword / expression (where words may be appended)
    bool percent = false;       ///< a '%' program delimiter / header line (Sinumerik %_N_…)
    bool spaced = false;        ///< words are separated by white space
    bool lowerCase = false;     ///< the last word letter was lower case
    bool hasComment = false;    ///< the block holds a comment

    /// First word with `letter` (upper case), or nullptr.
    const Word* find(char letter) const {
        for (int i = 0; i < count; ++i)
            if (words[i].letter == letter) return &words[i];
        return nullptr;
    }
    std::string_view identifier(std::string_view line, int i) const {
        return line.substr(identifiers[i].begin, identifiers[i].end - identifiers[i].begin);
    }
};

/// Lexes one block. `firstLine`: the block is the first of the file (a UTF-8 byte-order mark is skipped).
/// Never throws; problems are flags.
void lexBlock(std::string_view line, Dialect dialect, LexedBlock& out, bool firstLine = false);

/// What a line longer than the reader's buffer (it comes in pieces and is never lexed whole) may change, gathered
/// piece by piece in constant memory: comments are skipped as the lexer skips them, the word letters outside them
/// are collected.
struct OverlongLine {
    bool inParen = false;    ///< inside a ( … ) comment at the end of the last piece
    bool inComment = false;  ///< after a ';' comment start: the rest of the line is comment
    bool code = false;       ///< something other than white space and comments
    bool other = false;      ///< characters that are not plain words: '#', '[', '=', '$', '<', control bytes …
    uint32_t letters = 0;    ///< word letters outside comments (bit letter − 'A', upper case)
    bool lastWasLetter = false;
    void reset() { *this = OverlongLine{}; }
    void feed(std::string_view piece);
    bool has(char upperLetter) const { return (letters >> (upperLetter - 'A')) & 1u; }
};

/// Parses a plain G-code number ("-12.500", "+.5", "3.") as the lexer does. Returns false on anything else.
bool parseGcodeNumber(std::string_view text, double& value);

}  // namespace cnccomp::postproc
