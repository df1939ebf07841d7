// `cnccomp correct` refusing what it cannot do right: a tool length nobody gave where a rotary
// move's correction depends on it (a test program's header names its length and is read), a correction that does not
// converge (exit 3, nothing written unless --keep-partial), and one word in exponent notation in a milling program
// (no longer a 3-D printer clue for --dialect auto: the rs274ngc lexer refuses that line).
#include <gtest/gtest.h>

#include <filesystem>
#include <sstream>
#include <vector>

#include <fmt/format.h>

#include "cnccomp/io/deviation_csv.hpp"
#include "postproc/dialect.hpp"
#include "postproc/correct_program.hpp"
#include "test_support.hpp"

namespace cnccomp::postproc {
namespace {

namespace fs = std::filesystem;

const std::string kMachine = test::sourcePath("samples/machines/multitasking.xml");
const std::string kTruth = test::sourcePath("samples/deviations/multitasking-truth.csv");
const std::string kPlan = test::sourcePath("samples/plans/multitasking-six-circles.xml");

std::string correctArgs(const std::string& in, const std::string& out) {
    return "correct --machine " + kMachine + " --deviations " + kTruth + " --in " + in + " --out " + out;
}

std::string upper(std::string s) {
    for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    return s;
}

/// The test program of the plan's run `run`, written by `cnccomp testprog` into `dir`/tp. Fanuc: its programs give
/// the tool length only in the header (LinuxCNC's give it by G43.1 as well, see the last test).
std::string testProgram(const test::ScratchDir& dir, const std::string& run, const std::string& dialect = "fanuc") {
    if (!fs::exists(dir.file("tp"))) {
        const auto r = test::runCli("testprog --machine " + kMachine + " --plan " + kPlan + " --dialect " + dialect + " --out " +
                                    dir.file("tp"));
        EXPECT_EQ(r.exitCode, 0) << r.out;
    }
    // File names are TP<nn>_<run>.<ext> with '-' written as '_' (postproc/testprog).
    std::string key = run;
    std::replace(key.begin(), key.end(), '-', '_');
    for (const auto& e : fs::directory_iterator(dir.file("tp")))
        if (e.path().filename().string().find(key) != std::string::npos) return e.path().string();
    ADD_FAILURE() << "no program for " << run;
    return {};
}

TEST(PostprocCorrectGuards, HeaderToolLengthIsFoundCaseInsensitively) {
    // The header lines as cnccomp testprog writes them (postproc/testprog/test_program.cpp): LinuxCNC, Fanuc
    // (upper case), Klartext (a numbered ';' block).
    auto h = toolLengthFromHeader("%\n(run B-X)\n(to correct this program for the measured machine: cnccomp correct "
                                  "--tool-length 360)\nG0 X0\n");
    ASSERT_TRUE(h);
    EXPECT_EQ(h->mm, 360);
    EXPECT_EQ(h->line, 3u);
    h = toolLengthFromHeader("O1001 (X)\n(TO CORRECT THIS PROGRAM FOR THE MEASURED MACHINE: CNCCOMP CORRECT --TOOL-LENGTH 100.5)\n");
    ASSERT_TRUE(h);
    EXPECT_EQ(h->mm, 100.5);
    h = toolLengthFromHeader("0 BEGIN PGM TP01 MM\n1 ; to correct this program: cnccomp correct --tool-length 0\n");
    ASSERT_TRUE(h);
    EXPECT_EQ(h->mm, 0);
    EXPECT_FALSE(toolLengthFromHeader("G0 X0\n(cnccomp correct --tool-length)\n(cnccomp correct --tool-length abc)\n"));
}

TEST(PostprocCorrectGuards, TestProgramWithoutToolLengthOptionTakesItsHeaders) {
    // Oracle: the same program corrected with the length given on the command line (the header's number) gives the
    // same bytes. With an assumed 0 they left 45 um on the true machine, so on some of them the output for 0
    // differs.
    test::ScratchDir dir("pp-guard-header");
    (void)testProgram(dir, "C-radial");
    int differs = 0, programs = 0;
    for (const auto& e : fs::directory_iterator(dir.file("tp"))) {
        if (e.path().extension() != ".nc") continue;
        ++programs;
        const std::string p = e.path().string(), text = upper(test::readText(p));  // Fanuc comments are upper case
        const size_t at = text.find("CNCCOMP CORRECT --TOOL-LENGTH ");
        ASSERT_NE(at, std::string::npos) << p;
        const std::string length = text.substr(at + 30, text.find(')', at) - at - 30);
        auto r = test::runCli(correctArgs(p, dir.file("a.nc")));
        ASSERT_EQ(r.exitCode, 0) << r.out;
        EXPECT_NE(r.out.find("tool length: " + length + " mm, from the program's header"), std::string::npos) << r.out;
        r = test::runCli(correctArgs(p, dir.file("b.nc")) + " --tool-length " + length);
        ASSERT_EQ(r.exitCode, 0) << r.out;
        EXPECT_EQ(r.out.find("from the program's header"), std::string::npos) << r.out;
        EXPECT_EQ(test::readText(dir.file("a.nc")), test::readText(dir.file("b.nc"))) << p;
        r = test::runCli(correctArgs(p, dir.file("c.nc")) + " --tool-length 0");
        ASSERT_EQ(r.exitCode, 0) << r.out;
        if (test::readText(dir.file("a.nc")) != test::readText(dir.file("c.nc"))) ++differs;
        for (const char* f : {"a.nc", "b.nc", "c.nc"}) fs::remove(dir.file(f));
    }
    EXPECT_EQ(programs, 6);
    EXPECT_GE(differs, 1);
}

// LinuxCNC test programs give their tool length by G43.1 Z<L> (Z words written minus L): `correct` takes the length
// from it, with or without the header line, and the result is the one for --tool-length L.
TEST(PostprocCorrectGuards, LinuxcncTestProgramGivesItsToolLengthByG431) {
    test::ScratchDir dir("pp-guard-g431");
    const std::string p = testProgram(dir, "B-X", "linuxcnc");
    std::string text = test::readText(p);
    const size_t at = text.find("cnccomp correct --tool-length ");
    ASSERT_NE(at, std::string::npos);
    const std::string length = text.substr(at + 30, text.find(')', at) - at - 30);
    EXPECT_NE(text.find("G43.1 Z" + length + ".000000"), std::string::npos) << length;
    text.replace(at, 29, "header line removed");
    test::writeText(dir.file("p.ngc"), text);
    auto r = test::runCli(correctArgs(dir.file("p.ngc"), dir.file("a.ngc")));
    ASSERT_EQ(r.exitCode, 0) << r.out;
    r = test::runCli(correctArgs(dir.file("p.ngc"), dir.file("b.ngc")) + " --tool-length " + length);
    ASSERT_EQ(r.exitCode, 0) << r.out;
    EXPECT_EQ(test::readText(dir.file("a.ngc")), test::readText(dir.file("b.ngc")));
}

TEST(PostprocCorrectGuards, RotaryProgramWithoutAnyToolLengthIsRefusedUnlessZeroIsGiven) {
    test::ScratchDir dir("pp-guard-nolength");
    (void)testProgram(dir, "C-radial");
    int refused = 0;
    for (const auto& e : fs::directory_iterator(dir.file("tp"))) {
        if (e.path().extension() != ".nc") continue;
        std::string text = test::readText(e.path().string());
        const size_t at = upper(text).find("CNCCOMP CORRECT --TOOL-LENGTH");
        ASSERT_NE(at, std::string::npos);
        text.replace(at, 29, "header line removed");
        test::writeText(dir.file("p.nc"), text);
        auto r = test::runCli(correctArgs(dir.file("p.nc"), dir.file("o.nc")));
        if (r.exitCode == 2) {
            ++refused;
            for (const char* s : {"p.nc:", "depends on the tool length", "--tool-length 0 when 0 is meant"})
                EXPECT_NE(r.out.find(s), std::string::npos) << s << "\n" << r.out;
            EXPECT_FALSE(fs::exists(dir.file("o.nc")));
        } else {
            EXPECT_EQ(r.exitCode, 0) << r.out;
        }
        r = test::runCli(correctArgs(dir.file("p.nc"), dir.file("o.nc")) + " --tool-length 0");
        EXPECT_EQ(r.exitCode, 0) << r.out;
        EXPECT_TRUE(fs::exists(dir.file("o.nc")));
        fs::remove(dir.file("o.nc"));
    }
    EXPECT_GE(refused, 1);
    // A program without rotary moves needs no length: the multitasking machine's linear moves at B = C = 0.
    test::writeText(dir.file("lin.ngc"), "G21 G90\nG0 X10 Y0 Z50\nG1 X20 Y5 Z40 F500\nG1 X30 Y-5 Z45\nM2\n");
    const auto r = test::runCli(correctArgs(dir.file("lin.ngc"), dir.file("lin-out.ngc")));
    EXPECT_EQ(r.exitCode, 0) << r.out;
}

TEST(PostprocCorrectGuards, CorrectionThatDoesNotConvergeWritesNothingUnlessKeepPartial) {
    // A correction that cannot meet its goal: the sample truth x 395 (mm offsets, up to 0.99 deg of tilt: still inside
    // the range the deviation reader accepts, src/cnccomp/io/deviation_range.hpp) and a tolerance of 1e-5 um with nine
    // decimals (so the tolerance is not raised to the digits): the moves of the sample 5-axis program split to the
    // subdivision limit without meeting it. (The first version of this test used the truth x 20000, which the reader now
    // refuses as beyond any machine.)
    test::ScratchDir dir("pp-guard-converge");
    const std::string truth = test::readText(kTruth);
    std::istringstream rows(truth);
    std::string line, absurd;
    while (std::getline(rows, line)) {
        if (line.empty() || line[0] == '#' || line.rfind("name,", 0) == 0) {
            absurd += line + "\n";
            continue;
        }
        std::vector<std::string> c;
        std::stringstream cells(line);
        for (std::string cell; std::getline(cells, cell, ',');) c.push_back(cell);
        ASSERT_EQ(c.size(), 5u) << line;
        absurd += fmt::format("{},{},{},{},{}\n", c[0], c[1], std::stod(c[2]) * 395, c[3], std::stod(c[4]) * 395);
    }
    test::writeText(dir.file("absurd.csv"), absurd);
    std::string program;
    std::istringstream sample(test::readText(test::sourcePath("samples/gcode/multitasking-5axis.ngc")));
    for (int k = 0; k < 20 && std::getline(sample, line); ++k) program += line + "\n";
    test::writeText(dir.file("p.ngc"), program + "M2\n");
    const std::string args = "correct --machine " + kMachine + " --deviations " + dir.file("absurd.csv") + " --in " +
                             dir.file("p.ngc") + " --out " + dir.file("o.ngc") +
                             " --tool-length H1=100 --tol-um 0.00001 --decimals 9 --report " + dir.file("r.csv");
    auto r = test::runCli(args);
    EXPECT_EQ(r.exitCode, 3) << r.out;
    EXPECT_NE(r.out.find("the correction did not converge"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("nothing written"), std::string::npos) << r.out;
    EXPECT_FALSE(fs::exists(dir.file("o.ngc")));
    EXPECT_FALSE(fs::exists(dir.file("r.csv")));
    r = test::runCli(args + " --keep-partial");
    EXPECT_EQ(r.exitCode, 3) << r.out;
    EXPECT_NE(r.out.find("--keep-partial"), std::string::npos) << r.out;
    EXPECT_TRUE(fs::exists(dir.file("o.ngc")));
    EXPECT_TRUE(fs::exists(dir.file("r.csv")));
}

TEST(PostprocCorrectGuards, ExponentWordDoesNotMakeAMillingProgramPrinterCode) {
    // Before: "G1 X1e1" counted as an extruder word (X1 E1), the program was read as printer code.
    const std::string program = "G21 G90\nG0 X0 Y0 Z50\nG1 X1e1 Y5 F500\nG1 X20 Y5\nM2\n";
    const DetectedDialect d = detectDialect(program);
    EXPECT_EQ(d.dialect, Dialect::Rs274ngc) << d.reason;
    EXPECT_FALSE(d.certain);
    // Printer code is still recognised by its E words, also written right after G1.
    EXPECT_EQ(detectDialect("G28\nG1 X10 Y10 E0.5 F1200\n").dialect, Dialect::Printer);
    EXPECT_EQ(detectDialect("G28\nG1E5 F1800\n").dialect, Dialect::Printer);
    test::ScratchDir dir("pp-guard-exp");
    test::writeText(dir.file("p.ngc"), program);
    const auto r = test::runCli(correctArgs(dir.file("p.ngc"), dir.file("o.ngc")));
    ASSERT_EQ(r.exitCode, 0) << r.out;
    EXPECT_NE(r.out.find("dialect: rs274ngc"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("line 3: "), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("exponent notation"), std::string::npos) << r.out;
    const std::string out = test::readText(dir.file("o.ngc"));
    EXPECT_NE(out.find("G1 X1e1 Y5 F500\n"), std::string::npos) << out;  // passed through as written
    EXPECT_EQ(out.find("X0.97"), std::string::npos) << out;  // not read as X1 E1 and rewritten as X0.9717e1
}

}  // namespace
}  // namespace cnccomp::postproc
