// Bad programs give clear errors or reported pass-through, never a crash or a half-written file: empty files,
// binary junk, unterminated comments, 10 000-character lines, NaN / huge numbers, lines longer than the read
// buffer, random printable garbage; and the command line refuses to overwrite its input.
#include <gtest/gtest.h>

#include <filesystem>
#include <random>
#include <sstream>

#include "cnccomp/error.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "postproc/processor.hpp"
#include "test_support.hpp"

namespace cnccomp::pp {
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
        "G1 X1e400 Y5 Z100 B0 C0\n"                     // 'e' is not part of a number: an E word (harmless)
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
        if (line >= 2 && line <= 7 && line != 4) {
            EXPECT_EQ(la, lb) << "line " << line << " must pass through unchanged";
        }
    EXPECT_TRUE(reported(s, 2, "unterminated comment"));
    EXPECT_TRUE(reported(s, 3, "number"));
    EXPECT_TRUE(reported(s, 5, "keyword"));
    EXPECT_TRUE(reported(s, 6, "out of range"));
    EXPECT_TRUE(reported(s, 7, "binary"));
    EXPECT_GE(s.passedThrough, 5u);
    EXPECT_EQ(s.moves, 3u) << formatSummary(s);  // lines 1, 4 and 8 are corrected
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

}  // namespace
}  // namespace cnccomp::pp
