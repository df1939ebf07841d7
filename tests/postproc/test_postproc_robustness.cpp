// Bad programs give clear errors or reported pass-through, never a crash or a half-written file: empty files,
// binary junk, unterminated comments, 10 000-character lines, NaN / huge numbers, lines longer than the read
// buffer, random printable garbage; and the command line refuses to overwrite its input.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <random>
#include <sstream>

#include "cnccomp/error.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "postproc/lexer.hpp"
#include "postproc/correct_program.hpp"
#include "test_support.hpp"

namespace cnccomp::postproc {
using namespace cnccomp::io;
namespace {

const DeviationSet& truth() {
    static const DeviationSet d =
        readDeviationCsv(test::sourcePath("samples/deviations/multitasking-truth.csv"), test::multitasking());
    return d;
}

CorrectSummary correctText(const std::string& program, std::string& out, CorrectOptions o = {}) {
    std::istringstream in(program);
    std::ostringstream os;
    o.inputName = "test.nc";
    if (o.setup.defaultToolLength == 0) o.setup.addToolLength("100");
    const CorrectSummary s = correctProgram(test::multitasking(), truth(), in, os, o);
    out = os.str();
    return s;
}

bool reported(const CorrectSummary& s, uint64_t line, const std::string& words) {
    for (const Notice& n : s.passThrough)
        if (n.line == line && n.message.find(words) != std::string::npos) return true;
    return false;
}

TEST(PostprocRobustness, EmptyAndBinaryInputsAreClearErrors) {
    std::string out;
    try {
        correctText("", out);
        FAIL() << "an empty program must be refused";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("test.nc"), std::string::npos);
        EXPECT_NE(std::string(e.what()).find("empty"), std::string::npos);
    }
    std::string junk = "G0 X1\n";
    std::mt19937_64 rng(2);
    for (int i = 0; i < 4000; ++i) junk.push_back(static_cast<char>(rng() & 0xff));
    try {
        correctText(junk, out);
        FAIL() << "binary junk must be refused";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("binary"), std::string::npos) << e.what();
    }
}

TEST(PostprocRobustness, ProblemBlocksPassThroughUnchangedAndAreReported) {
    const std::string program =
        "G21 G90 G0 X10 Y0 Z100 B0 C0\n"
        "G1 X20 (unterminated comment\n"
        "G1 X" + std::string(400, '9') + "\n"        // does not fit a double
        "G1 X1e400 Y5 Z100 B0 C0\n"                     // exponent notation: not G-code, never read as X1
        "G1 XNAN\n"
        "G1 X123456789012345 Y0 Z100\n"                 // finite but absurd
        "G1 X\x01\x02 Y0\n"                             // control bytes
        "G1 X30 Y0 Z100 B0 C0\n";
    std::string out;
    CorrectOptions o;
    o.dialect = Dialect::Rs274ngc;
    const CorrectSummary s = correctText(program, out, o);
    std::istringstream a(program), b(out);
    std::string la, lb;
    for (int line = 1; std::getline(a, la) && std::getline(b, lb); ++line)
        if (line >= 2 && line <= 7) {
            EXPECT_EQ(la, lb) << "line " << line << " must pass through unchanged";
        }
    EXPECT_TRUE(reported(s, 2, "unterminated comment"));
    EXPECT_TRUE(reported(s, 3, "number"));
    EXPECT_TRUE(reported(s, 4, "exponent"));
    EXPECT_TRUE(reported(s, 5, "keyword"));
    EXPECT_TRUE(reported(s, 6, "out of range"));
    EXPECT_TRUE(reported(s, 7, "binary"));
    EXPECT_GE(s.passedThrough, 6u);
    EXPECT_EQ(s.moves, 2u) << formatSummary(s);  // lines 1 and 8 are corrected
}

TEST(PostprocRobustness, TenThousandCharacterLines) {
    std::string program = "G21 G90 G0 X10 Y0 Z100 B0 C0\n(" + std::string(10000, 'c') + ")\n";
    std::string words = "G1";
    for (int i = 0; i < 2500; ++i) words += " X1";
    program += words + "\n";
    program += "G1 X10 Y0 Z101 B0 C0 ; " + std::string(10000, ';') + "\n";
    std::string out;
    const CorrectSummary s = correctText(program, out);
    EXPECT_EQ(s.lines, 4u);
    EXPECT_TRUE(reported(s, 3, "too many words"));
    EXPECT_NE(out.find(std::string(10000, 'c')), std::string::npos);
    EXPECT_NE(out.find(std::string(10000, ';')), std::string::npos);
    EXPECT_EQ(s.moves, 2u);
}

TEST(PostprocRobustness, LinesLongerThanTheBufferPassThroughInPieces) {
    const std::string longLine = "G1 X5 (" + std::string(5000, 'x') + ")";
    const std::string program = "G21 G90 G0 X10 Y0 Z100 B0 C0\n" + longLine + "\r\nG0 X10 Y0 Z100\n";
    CorrectOptions o;
    o.bufferSize = 1024;
    std::string out;
    const CorrectSummary s = correctText(program, out, o);
    EXPECT_NE(out.find(longLine + "\r\n"), std::string::npos);
    EXPECT_TRUE(reported(s, 2, "longer than"));
    EXPECT_EQ(s.lines, 3u);
}

TEST(PostprocRobustness, AfterAnOverlongLineLineNumbersAndPositionsStayRight) {
    // A three-axis program on the five-axis machine (B and C never named, taken at 0). A comment line longer than the
    // buffer changes nothing; a line of plain axis words longer than the buffer forgets only the axes it names.
    const std::string comment = "(" + std::string(5000, 'c') + ")";
    const std::string program = "G21 G90 G0 X10 Y0 Z100\n" + comment + "\nG1 X20 F100\nG1 X30\n" +  // lines 1-4
                                "G1 X40 Y[1+2]\n" +                                                   // line 5
                                "X5 (" + std::string(3000, 'x') + ")\n" +                            // line 6
                                "G1 Y3\nG1 X7 Y3\n";                                                 // lines 7-8
    CorrectOptions o;
    o.dialect = Dialect::Rs274ngc;
    o.bufferSize = 1024;
    std::string out;
    const CorrectSummary s = correctText(program, out, o);
    EXPECT_EQ(s.lines, 8u);
    EXPECT_TRUE(reported(s, 5, "expression")) << formatSummary(s);
    EXPECT_TRUE(reported(s, 6, "positions of X unknown")) << formatSummary(s);
    EXPECT_TRUE(reported(s, 7, "position of an axis not known")) << formatSummary(s);
    EXPECT_FALSE(reported(s, 2, "longer than")) << "a comment-only line changes nothing";
    EXPECT_EQ(s.moves, 4u) << formatSummary(s);  // lines 1, 3, 4 and 8: B and C stay known after the long comment
    EXPECT_NE(out.find(comment + "\n"), std::string::npos);
}

TEST(PostprocRobustness, CarriageReturnOnlyLineEndsAreLineEnds) {
    const std::string program = "G21 G90 G0 X10 Y0 Z100 B0 C0\rG1 X20 F100\rG1 X30 Y5\r";
    std::string out;
    CorrectOptions o;
    o.dialect = Dialect::Rs274ngc;
    const CorrectSummary s = correctText(program, out, o);
    EXPECT_EQ(s.lines, 3u);
    EXPECT_EQ(s.moves, 3u) << formatSummary(s);
    EXPECT_EQ(s.corrected, 3u);
    EXPECT_EQ(std::count(out.begin(), out.end(), '\r'), 3);
    EXPECT_EQ(out.find('\n'), std::string::npos);
    ASSERT_FALSE(s.warnings.empty());
    EXPECT_NE(s.warnings[0].message.find("lone CR"), std::string::npos);
    // Identity keeps every byte.
    std::istringstream in(program);
    std::ostringstream os;
    const CorrectSummary z = correctProgram(test::multitasking(), DeviationSet(test::multitasking()), in, os, o);
    EXPECT_EQ(os.str(), program);
    EXPECT_EQ(z.moves, 3u);
}

TEST(PostprocRobustness, ExponentNotationIsNeverReadAsAShorterNumber) {
    const std::string program = "G21 G90 G0 X10 Y0 Z100 B0 C0\nG1 X1e-3 Y5 F100\nG1 Y6\nG1 X2E2 Y7\nG1 X3 Y8\n";
    std::string out;
    CorrectOptions o;
    o.dialect = Dialect::Rs274ngc;
    const CorrectSummary s = correctText(program, out, o);
    EXPECT_TRUE(reported(s, 2, "exponent")) << formatSummary(s);
    EXPECT_TRUE(reported(s, 3, "not known")) << "X is unknown after X1e-3, not 1 mm";
    EXPECT_TRUE(reported(s, 4, "exponent"));
    EXPECT_EQ(s.moves, 2u);  // lines 1 and 5
    std::istringstream a(program), b(out);
    std::string la, lb;
    for (int line = 1; std::getline(a, la) && std::getline(b, lb); ++line)
        if (line >= 2 && line <= 4) {
            EXPECT_EQ(la, lb);
        }
    // Printers end the number at 'E' (Marlin): X2 and an extruder word.
    LexedBlock blk;
    lexBlock("G1 X2E0.5", Dialect::Printer, blk);
    ASSERT_EQ(blk.count, 3);
    EXPECT_EQ(blk.words[1].value, 2.0);
    EXPECT_EQ(blk.words[2].letter, 'E');
    lexBlock("G1 X2e-3", Dialect::Fanuc, blk);
    EXPECT_TRUE(blk.flags & kExponent);
}

TEST(PostprocRobustness, RandomPrintableGarbageNeverCrashes) {
    std::mt19937_64 rng(77);
    const std::string alphabet = "GXYZABCIJKRFMNOPQ0123456789.-+ ()[]#=;%/*\"$<>\t";
    for (int trial = 0; trial < 200; ++trial) {
        std::string program;
        const int lines = 1 + static_cast<int>(rng() % 30);
        for (int l = 0; l < lines; ++l) {
            const int len = static_cast<int>(rng() % 60);
            for (int k = 0; k < len; ++k) program.push_back(alphabet[rng() % alphabet.size()]);
            program += (rng() % 3 == 0) ? "\r\n" : "\n";
        }
        program.insert(0, "G0 X0 Y0 Z100 B0 C0\n");
        for (const auto d : {Dialect::Rs274ngc, Dialect::Fanuc, Dialect::Sinumerik, Dialect::Printer}) {
            CorrectOptions o;
            o.dialect = d;
            std::string out;
            ASSERT_NO_THROW(correctText(program, out, o)) << program;
            // Every line of the input is in the output, in order (new lines may be added in between).
            size_t pos = 0;
            std::istringstream in(program);
            std::string line;
            size_t lineCount = 0;
            while (std::getline(in, line)) ++lineCount;
            EXPECT_GE(static_cast<size_t>(std::count(out.begin(), out.end(), '\n')), lineCount);
            (void)pos;
        }
    }
}

TEST(PostprocRobustness, CommandLineErrorsNameTheProblem) {
    test::ScratchDir dir("pp-cli-errors");
    const std::string m = test::sourcePath("samples/machines/multitasking.xml");
    const std::string d = test::sourcePath("samples/deviations/multitasking-truth.csv");
    const std::string p = dir.file("p.nc");
    test::writeText(p, "G0 X1 Y2 Z3\n");
    auto r = test::runCli("correct --machine " + m + " --deviations " + d + " --in " + p + " --out " + p);
    EXPECT_EQ(r.exitCode, 2) << r.out;
    EXPECT_NE(r.out.find("overwrite"), std::string::npos) << r.out;
    EXPECT_EQ(test::readText(p), "G0 X1 Y2 Z3\n");
    r = test::runCli("correct --machine " + m + " --deviations " + d + " --in " + p + " --out " + dir.file("o.nc") +
                     " --work-offset G54=1,2");
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_NE(r.out.find("--work-offset"), std::string::npos) << r.out;
    EXPECT_FALSE(std::filesystem::exists(dir.file("o.nc")));
    test::writeText(dir.file("empty.nc"), "");
    r = test::runCli("correct --machine " + m + " --deviations " + d + " --in " + dir.file("empty.nc") + " --out " +
                     dir.file("o.nc"));
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_NE(r.out.find("empty.nc"), std::string::npos) << r.out;
    EXPECT_FALSE(std::filesystem::exists(dir.file("o.nc")));  // no half file
    r = test::runCli("correct --machine " + m + " --deviations " + d + " --in " + p + " --out " + dir.file("o.nc") +
                     " --dialect heidenhain");
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_NE(r.out.find("dialect"), std::string::npos) << r.out;
}


TEST(PostprocRobustness, HeidenhainKlartextProgramGoesToTheKlartextCorrector) {
    // A Klartext program (block numbers, BEGIN PGM, L ... R0 FMAX) looks like ISO words to the G-code lexer: it is
    // recognised from BEGIN PGM whatever --dialect says and corrected by the Klartext corrector
    // (postproc/klartext_correct.hpp; tests/postproc/test_postproc_klartext_correct.cpp checks what it writes).
    test::ScratchDir dir("pp-klartext");
    const std::string m = test::sourcePath("samples/machines/table-table-ac.xml");
    const std::string d = test::sourcePath("samples/deviations/table-table-ac-truth.csv");
    const std::string p = dir.file("part.h"), o = dir.file("out.h");
    test::writeText(p, "; probe part\n0 BEGIN PGM PART MM\n1 TOOL CALL 1 Z S3000\n2 L X+10 Y+20 Z+50 A+30 C+0 R0 FMAX\n"
                       "3 L X+15 F500\n4 END PGM PART MM\n");
    for (const char* extra : {"", " --dialect rs274ngc", " --dialect fanuc", " --dialect heidenhain"}) {
        std::filesystem::remove(o);
        const auto r = test::runCli("correct --machine " + m + " --deviations " + d + " --in " + p + " --out " + o +
                                    " --tool-length 100 --strict" + extra);
        EXPECT_EQ(r.exitCode, 0) << extra << r.out;
        EXPECT_NE(r.out.find("dialect: heidenhain"), std::string::npos) << r.out;
        EXPECT_NE(r.out.find("moves evaluated: 2;"), std::string::npos) << r.out;
        const std::string out = test::readText(o);
        EXPECT_EQ(out.rfind("; probe part\n0 BEGIN PGM PART MM\n1 TOOL CALL 1 Z S3000\n2 L X+", 0), 0u) << out;
        EXPECT_NE(out, test::readText(p));
    }
    // The library too (detected, or CorrectOptions::dialect Heidenhain).
    const MachineModel mm = readMachineXml(m);
    std::istringstream in(test::readText(p));
    std::ostringstream out;
    CorrectOptions co;
    co.inputName = "part.h";
    EXPECT_EQ(correctProgram(mm, DeviationSet(mm), in, out, co).dialect, Dialect::Heidenhain);
    EXPECT_EQ(out.str(), test::readText(p));
    // Forced on a program without BEGIN PGM: refused before anything is written.
    std::istringstream iso("G0 X1 Y2 Z3\n");
    std::ostringstream none;
    co.dialect = Dialect::Heidenhain;
    EXPECT_THROW(correctProgram(mm, DeviationSet(mm), iso, none, co), InputError);
    EXPECT_TRUE(none.str().empty());
}

}  // namespace
}  // namespace cnccomp::postproc
