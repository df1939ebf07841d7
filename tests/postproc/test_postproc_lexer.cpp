// G-code lexer, line reader, number formatting and dialect detection: spans that let the writer keep every
// untouched byte, numbers parsed exactly as strtod, flags for everything that cannot be evaluated.
#include <gtest/gtest.h>

#include <cstdlib>
#include <random>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "postproc/dialect.hpp"
#include "postproc/lexer.hpp"
#include "postproc/line_reader.hpp"
#include "cnccomp/io/number_format.hpp"

namespace cnccomp::postproc {
using namespace cnccomp::io;
namespace {

std::string_view text(std::string_view line, const Word& w) { return line.substr(w.valueBegin, w.end - w.valueBegin); }

TEST(PostprocLexer, WordsCarryExactSpansAndValues) {
    const std::string line = "N10 G01 X-12.500 y.25 Z+3. F1500 (feed) ; rest";
    LexedBlock b;
    lexBlock(line, Dialect::Rs274ngc, b);
    ASSERT_EQ(b.count, 6);
    EXPECT_EQ(b.flags & kNotEvaluable, 0u);
    EXPECT_TRUE(b.hasComment);
    EXPECT_TRUE(b.spaced);
    EXPECT_EQ(b.words[0].letter, 'N');
    EXPECT_EQ(b.words[1].letter, 'G');
    EXPECT_EQ(b.words[1].digitsBefore, 2);
    const Word& x = b.words[2];
    EXPECT_EQ(x.letter, 'X');
    EXPECT_EQ(text(line, x), "-12.500");
    EXPECT_DOUBLE_EQ(x.value, -12.5);
    EXPECT_EQ(x.decimals, 3);
    EXPECT_TRUE(x.trailingZero);
    const Word& y = b.words[3];
    EXPECT_EQ(y.letter, 'Y');
    EXPECT_TRUE(y.lower);
    EXPECT_TRUE(y.bareFraction);
    EXPECT_DOUBLE_EQ(y.value, 0.25);
    const Word& z = b.words[4];
    EXPECT_TRUE(z.plus);
    EXPECT_TRUE(z.point);
    EXPECT_EQ(z.decimals, 0);
    EXPECT_DOUBLE_EQ(z.value, 3.0);
    EXPECT_FALSE(b.words[5].point);
    // Where new words are appended: right after the last word, before the comment.
    EXPECT_EQ(line.substr(b.codeEnd, 7), " (feed)");
}

TEST(PostprocLexer, NumbersParseExactlyLikeStrtod) {
    std::mt19937_64 rng(11);
    std::uniform_int_distribution<int> digits(0, 9), len(1, 17), dec(0, 8);
    for (int trial = 0; trial < 3000; ++trial) {
        std::string s = trial % 2 ? "-" : "";
        const int n = len(rng), d = std::min(dec(rng), n);
        for (int k = 0; k < n - d; ++k) s.push_back(static_cast<char>('0' + digits(rng)));
        if (d > 0 || trial % 3 == 0) s.push_back('.');
        for (int k = 0; k < d; ++k) s.push_back(static_cast<char>('0' + digits(rng)));
        if (s == "-" || s == "." || s == "-.") continue;
        double v = 0;
        ASSERT_TRUE(parseGcodeNumber(s, v)) << s;
        EXPECT_EQ(v, std::strtod(s.c_str(), nullptr)) << s;
    }
    double v;
    EXPECT_FALSE(parseGcodeNumber("", v));
    EXPECT_FALSE(parseGcodeNumber("1e5", v));
    EXPECT_FALSE(parseGcodeNumber("--1", v));
    EXPECT_FALSE(parseGcodeNumber(".", v));
}

TEST(PostprocLexer, FlagsWhatCannotBeEvaluated) {
    LexedBlock b;
    auto flags = [&](const std::string& s, Dialect d = Dialect::Rs274ngc) {
        lexBlock(s, d, b);
        return b.flags;
    };
    EXPECT_TRUE(flags("G1 X[#1+2] Y3") & kExpression);
    EXPECT_TRUE(flags("G1 X#100 Y3", Dialect::Fanuc) & kVariable);
    EXPECT_TRUE(flags("#100=5.0 (depth)", Dialect::Fanuc) & kAssignment);
    EXPECT_TRUE(flags("#<depth> = 3") & kAssignment);
    EXPECT_TRUE(flags("G1 X10 (never closed") & kUnterminatedComment);
    EXPECT_TRUE(flags("IF [#1 GT 3] GOTO 10", Dialect::Fanuc) & kIdentifier);
    EXPECT_TRUE(flags("o100 sub") & kIdentifier);
    EXPECT_TRUE(flags("G99 G82 R0.1 Z-0.1227 P F15.04") & kMissingValue);
    EXPECT_TRUE(flags("G1 X1\x01") & kBinary);
    EXPECT_TRUE(flags("G1 X1 \xff\xfe") & kBinary);
    EXPECT_TRUE(flags("G1 X1 *12") & kUnknownChar);
    EXPECT_TRUE(flags("N140 CYCLE800(1,\"TC1\",0)", Dialect::Sinumerik) & kCall);
    EXPECT_TRUE(flags("N120 G1 X=R1 Y=R1*2", Dialect::Sinumerik) & kAssignment);
    EXPECT_TRUE(flags("R1=12.5", Dialect::Sinumerik) & kAssignment);
    // Harmless text: comments, printer messages.
    EXPECT_EQ(flags("G1 X1 (comment with [brackets] and #) ; and ; more") & kNotEvaluable, 0u);
    EXPECT_EQ(flags("M117 Printing (50%) now", Dialect::Printer) & kNotEvaluable, 0u);
    EXPECT_TRUE(b.flags & kTextArgument);
    // Bytes of any kind inside comments are fine.
    EXPECT_EQ(flags("G1 X1 (\xc3\xa9t\xc3\xa9 \x01)") & kNotEvaluable, 0u);
}

TEST(PostprocLexer, BlockDeletePercentAndByteOrderMark) {
    LexedBlock b;
    lexBlock("/2 G1 X5", Dialect::Fanuc, b);
    EXPECT_EQ(b.blockDelete, 0);
    ASSERT_EQ(b.count, 2);
    EXPECT_EQ(b.words[0].letter, 'G');
    lexBlock("%_N_PART_MPF", Dialect::Sinumerik, b);
    EXPECT_TRUE(b.percent);
    lexBlock("\xEF\xBB\xBFG0 X1", Dialect::Rs274ngc, b, true);
    EXPECT_EQ(b.flags & kNotEvaluable, 0u);
    ASSERT_EQ(b.count, 2);
    lexBlock("\xEF\xBB\xBFG0 X1", Dialect::Rs274ngc, b, false);
    EXPECT_TRUE(b.flags & kBinary);
}

TEST(PostprocLexer, UnspacedAndLowerCaseBlocks) {
    const std::string line = "g1z-.1f24";
    LexedBlock b;
    lexBlock(line, Dialect::Rs274ngc, b);
    ASSERT_EQ(b.count, 3);
    EXPECT_FALSE(b.spaced);
    EXPECT_TRUE(b.lowerCase);
    EXPECT_DOUBLE_EQ(b.words[1].value, -0.1);
    EXPECT_EQ(text(line, b.words[1]), "-.1");
    EXPECT_DOUBLE_EQ(b.words[2].value, 24);
}

TEST(PostprocLexer, TooManyWordsAndHugeLines) {
    std::string many;
    for (int i = 0; i < 5000; ++i) many += "X1";
    LexedBlock b;
    lexBlock(many, Dialect::Rs274ngc, b);
    EXPECT_TRUE(b.flags & kTooManyWords);
    std::string digits = "X" + std::string(400, '9');
    lexBlock(digits, Dialect::Rs274ngc, b);
    EXPECT_TRUE(b.flags & kBadNumber);  // 1e400 does not fit a double
    std::string comment = "(" + std::string(10000, 'c') + ")";
    lexBlock(comment, Dialect::Rs274ngc, b);
    EXPECT_EQ(b.flags & kNotEvaluable, 0u);
    EXPECT_EQ(b.count, 0);
}

TEST(PostprocLexer, FormatNumberRoundTripsAndKeepsStyles) {
    char buf[kMaxNumberChars];
    auto fmt = [&](double v, NumberStyle s) { return std::string(buf, formatNumber(v, s, buf)); };
    EXPECT_EQ(fmt(1.5, {4, true, false, false, true}), "1.5000");
    EXPECT_EQ(fmt(1.5, {4, false, false, false, true}), "1.5");
    EXPECT_EQ(fmt(1.0, {4, false, false, false, true}), "1.");
    EXPECT_EQ(fmt(0.25, {3, false, true, false, true}), ".25");
    EXPECT_EQ(fmt(-0.25, {3, false, true, false, true}), "-.25");
    EXPECT_EQ(fmt(2.0, {3, true, false, true, true}), "+2.000");
    EXPECT_EQ(fmt(-0.00001, {3, true, false, false, true}), "0.000");  // never "-0.000"
    EXPECT_EQ(fmt(12345.0, {0, true, false, false, false}), "12345");
    EXPECT_EQ(fmt(-7.0, {0, true, false, false, false}), "-7");
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> u(-2000, 2000);
    for (int i = 0; i < 2000; ++i) {
        const double v = u(rng);
        for (int d : {0, 1, 3, 4, 6}) {
            const NumberStyle s{d, i % 2 == 0, false, false, true};
            double back = 0;
            ASSERT_TRUE(parseGcodeNumber(fmt(v, s), back)) << fmt(v, s);
            EXPECT_EQ(back, roundToStyle(v, s)) << v << " " << d;
            EXPECT_LE(std::fabs(back - v), 0.5 * std::pow(10.0, -d) * (1 + 1e-9));
        }
    }
}

TEST(PostprocLineReader, KeepsLineEndingsAndSplitsOverlongLines) {
    const std::string data = "G0 X1\r\nG1 Y2\n\nlast";
    std::istringstream in(data);
    LineReader r(in, 64);
    Line l;
    std::string rebuilt;
    int n = 0;
    while (r.next(l)) {
        rebuilt.append(l.text).append(l.eol);
        ++n;
    }
    EXPECT_EQ(rebuilt, data);
    EXPECT_EQ(n, 4);
    // A line longer than the buffer arrives in pieces, all flagged partial, bytes preserved.
    const std::string longLine = std::string(100, 'x') + "\r\n" + "G1 X1\n";
    std::istringstream in2(longLine);
    LineReader r2(in2, 16);
    rebuilt.clear();
    int partial = 0;
    while (r2.next(l)) {
        rebuilt.append(l.text).append(l.eol);
        partial += l.partial;
        if (!l.partial) {
            EXPECT_EQ(l.text, "G1 X1");
        }
    }
    EXPECT_EQ(rebuilt, longLine);
    EXPECT_GE(partial, 7);
}

TEST(PostprocLineReader, LoneCarriageReturnsEndLinesAndPiecesShareTheirLineNumber) {
    // Every split of "\r\n" across the buffer edge (buffer 16) is tried by shifting the data one byte at a time.
    for (size_t pad = 0; pad < 20; ++pad) {
        const std::string data = std::string(pad, ' ') + "G0 X1\rG1 Y2\r\nG1 Z3\n" + std::string(40, 'x') + "\rend";
        std::istringstream in(data);
        LineReader r(in, 16);
        Line l;
        std::string rebuilt;
        std::vector<std::pair<uint64_t, std::string>> eols;
        while (r.next(l)) {
            rebuilt.append(l.text).append(l.eol);
            if (l.lastPiece) eols.emplace_back(l.number, std::string(l.eol));
            if (l.partial) {
                EXPECT_TRUE(l.number == 4 || (l.number == 1 && pad + 5 >= 15)) << l.number;  // 15 + "\r" fill the buffer
            }
        }
        EXPECT_EQ(rebuilt, data) << pad;
        ASSERT_EQ(eols.size(), 5u) << pad;
        EXPECT_EQ(eols[0], std::make_pair(uint64_t{1}, std::string("\r")));
        EXPECT_EQ(eols[1], std::make_pair(uint64_t{2}, std::string("\r\n")));
        EXPECT_EQ(eols[2], std::make_pair(uint64_t{3}, std::string("\n")));
        EXPECT_EQ(eols[3], std::make_pair(uint64_t{4}, std::string("\r")));
        EXPECT_EQ(eols[4], std::make_pair(uint64_t{5}, std::string()));
        EXPECT_EQ(r.crOnlyEndings(), 2u);
    }
}

TEST(PostprocLineReader, OverlongLineScannerPassesOverCommentsAndCollectsWordLetters) {
    OverlongLine o;
    o.feed("(comment X1 G0");
    o.feed(" still comment) ");
    EXPECT_FALSE(o.code);
    o.feed("X5 Y-2.5 ; G0 Z1");
    o.feed(" B7");  // after ';': comment
    EXPECT_TRUE(o.code);
    EXPECT_TRUE(o.has('X') && o.has('Y'));
    EXPECT_FALSE(o.has('G') || o.has('Z') || o.has('B'));
    EXPECT_FALSE(o.other);
    o.reset();
    o.feed("GOTO1");
    EXPECT_TRUE(o.other);  // a keyword
    o.reset();
    o.feed("X#1");
    EXPECT_TRUE(o.other);
}

TEST(PostprocDialect, DetectsUnambiguousProgramsOnly) {
    EXPECT_EQ(detectDialect(";FLAVOR:Marlin\nG28\nG1 X1 E0.5\n").dialect, Dialect::Printer);
    EXPECT_EQ(detectDialect("%_N_PART_MPF\nN10 G0 X1\n").dialect, Dialect::Sinumerik);
    EXPECT_EQ(detectDialect("%\nO1234 (PART)\nG0 X1.\n").dialect, Dialect::Fanuc);
    EXPECT_EQ(detectDialect("#<depth> = 3\nG1 Z#<depth>\n").dialect, Dialect::Rs274ngc);
    EXPECT_FALSE(detectDialect("#1 = 3\nG1 Z#1\n").certain);  // numbered parameters: both families
    const DetectedDialect plain = detectDialect("G0 X1 Y2\nG1 Z-1 F100\n");
    EXPECT_EQ(plain.dialect, Dialect::Rs274ngc);
    EXPECT_FALSE(plain.certain);
    const DetectedDialect mixed = detectDialect("O1234\n;FLAVOR:Marlin\n");
    EXPECT_FALSE(mixed.certain);
    EXPECT_TRUE(detectDialect("(O1234 is only a comment)\nG0 X1\n").dialect == Dialect::Rs274ngc);
    EXPECT_EQ(parseDialect("LinuxCNC"), Dialect::Rs274ngc);
    EXPECT_EQ(parseDialect("marlin"), Dialect::Printer);
    EXPECT_FALSE(parseDialect("heidenhain"));
}

// One name table for reading, correcting and writing test programs. Oracle: the names each command accepted before the
// two tables (postproc::parseDialect, postproc::testprog::parseProgramDialect) were made one, transcribed from those two functions and
// the CLI (`correct` added heidenhain and klartext to the reader's names).
TEST(PostprocDialect, OneNameTableServesEveryUse) {
    using U = DialectUse;
    const auto accepted = [](U use) {
        std::vector<std::string> names;
        for (const char* n : {"rs274ngc", "linuxcnc", "rs274", "ngc", "fanuc", "haas", "sinumerik", "siemens", "printer",
                              "marlin", "reprap", "3d-printer", "heidenhain", "klartext", "tnc", "auto", "iso"})
            if (parseDialect(n, use)) names.emplace_back(n);
        return names;
    };
    using V = std::vector<std::string>;
    EXPECT_EQ(accepted(U::Read), (V{"rs274ngc", "linuxcnc", "rs274", "ngc", "fanuc", "haas", "sinumerik", "siemens",
                                    "printer", "marlin", "reprap", "3d-printer"}));
    EXPECT_EQ(accepted(U::Correct), (V{"rs274ngc", "linuxcnc", "rs274", "ngc", "fanuc", "haas", "sinumerik", "siemens",
                                       "printer", "marlin", "reprap", "3d-printer", "heidenhain", "klartext"}));
    EXPECT_EQ(accepted(U::Write), (V{"rs274ngc", "linuxcnc", "ngc", "fanuc", "sinumerik", "siemens", "heidenhain",
                                     "klartext", "tnc"}));
    EXPECT_EQ(parseDialect("TNC", U::Write), Dialect::Heidenhain);  // case-insensitive
    EXPECT_EQ(parseDialect("klartext", U::Correct), Dialect::Heidenhain);
    // The names the error messages list, and the names the programs and summaries carry.
    EXPECT_EQ(dialectNames(U::Read), "rs274ngc, fanuc, sinumerik, printer");
    EXPECT_EQ(dialectNames(U::Correct), "rs274ngc, fanuc, sinumerik, printer, heidenhain");
    EXPECT_EQ(dialectNames(U::Write), "linuxcnc, fanuc, sinumerik, heidenhain");
    EXPECT_STREQ(dialectName(Dialect::Rs274ngc), "rs274ngc");
    EXPECT_STREQ(dialectName(Dialect::Rs274ngc, U::Write), "linuxcnc");
    EXPECT_STREQ(dialectName(Dialect::Heidenhain), "heidenhain");
    EXPECT_STREQ(dialectName(Dialect::Printer, U::Write), "printer");
}

}  // namespace
}  // namespace cnccomp::postproc
