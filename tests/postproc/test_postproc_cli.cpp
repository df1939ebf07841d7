// `cnccomp correct` and `cnccomp poses` end to end: summary and report, setup files, number styles of the
// program kept in changed words, --tip-only, and the poses CSV read back against the program's own numbers.
#include <gtest/gtest.h>

#include <filesystem>
#include <sstream>

#include "cnccomp/error.hpp"
#include "cnccomp/io/csv.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "postproc/correct_program.hpp"
#include "test_support.hpp"

namespace cnccomp::postproc {
using namespace cnccomp::io;
namespace {

const std::string kMachine = test::sourcePath("samples/machines/multitasking.xml");
const std::string kTruth = test::sourcePath("samples/deviations/multitasking-truth.csv");

TEST(PostprocCli, CorrectPrintsASummaryAndWritesTheReport) {
    test::ScratchDir dir("pp-cli");
    const std::string in = test::sourcePath("samples/gcode/fanuc-macro.nc");
    const auto r = test::runCli("correct --machine " + kMachine + " --deviations " + kTruth + " --in " + in + " --out " +
                                dir.file("out.nc") + " --tool-length H1=100 --report " + dir.file("report.csv"));
    ASSERT_EQ(r.exitCode, 0) << r.out;
    for (const char* s : {"dialect: fanuc", "blocks read:", "blocks corrected:", "passed through unchanged:",
                          "largest correction:", "macro call (G65)", "subprogram call"})
        EXPECT_NE(r.out.find(s), std::string::npos) << s << "\n" << r.out;
    const CsvTable report = readCsv(dir.file("report.csv"));
    ASSERT_GE(report.rows.size(), 15u);
    bool g65 = false;
    for (const CsvRow& row : report.rows)
        if (report.cell(row, report.requireColumn("line")) == "23")
            g65 = report.cell(row, report.requireColumn("message")).find("G65") != std::string::npos;
    EXPECT_TRUE(g65) << "line 23 (G65) must be reported";
    EXPECT_NE(test::readText(dir.file("out.nc")), test::readText(in));
}

TEST(PostprocCli, PosesPrintsMachineCoordinates) {
    test::ScratchDir dir("pp-poses");
    test::writeText(dir.file("p.nc"), "G20 G90 G54\nG0 X1 Y2 Z0.5\nG91 G1 X-1 F10\n#1=2\nG90 G1 X#1\nG53 G0 Z0\n");
    const auto r = test::runCli("poses --in " + dir.file("p.nc") + " --dialect rs274ngc --work-offset G54=100,0,-50,0,0,30");
    ASSERT_EQ(r.exitCode, 0) << r.out;
    EXPECT_EQ(r.out,
              "line,motion,X,Y,Z,A,B,C\n"
              "2,G0,125.400000,50.800000,-37.300000,0.000000,0.000000,0.000000\n"
              "3,G1,100.000000,50.800000,-37.300000,0.000000,0.000000,0.000000\n"
              "5,-,,50.800000,-37.300000,0.000000,0.000000,0.000000\n"
              "6,G53,,50.800000,0.000000,0.000000,0.000000,0.000000\n");
    // With a machine: its axes only (no A on the multitasking machine).
    const auto m = test::runCli("poses --in " + dir.file("p.nc") + " --dialect linuxcnc --machine " + kMachine + " --out " +
                                dir.file("p.csv"));
    ASSERT_EQ(m.exitCode, 0) << m.out;
    const std::string csv = test::readText(dir.file("p.csv"));
    EXPECT_NE(csv.find("2,G0,25.400000,50.800000,12.700000,,0.000000,0.000000\n"), std::string::npos) << csv;
}

TEST(PostprocCli, PosesLabelToolTipMovesAndForgetSlidesAtAModeSwitch) {
    test::ScratchDir dir("pp-poses-tcp");
    test::writeText(dir.file("p.ngc"), "G21 G90\nG0 X1 Y2 Z3 A0 C0\nM428\nG1 X2 Y2 Z3 A-10 C5 F100\nM429\nG1 X3\n");
    const auto r = test::runCli("poses --in " + dir.file("p.ngc") + " --tcp-on M428 --tcp-off M429");
    ASSERT_EQ(r.exitCode, 0) << r.out;
    EXPECT_EQ(r.out,
              "line,motion,X,Y,Z,A,B,C\n"
              "2,G0,1.000000,2.000000,3.000000,0.000000,0.000000,0.000000\n"
              "4,G1 TCP,2.000000,2.000000,3.000000,-10.000000,0.000000,5.000000\n"
              "6,-,3.000000,,,-10.000000,0.000000,5.000000\n");
    const auto bad = test::runCli("poses --in " + dir.file("p.ngc") + " --tcp-on Q428");
    EXPECT_EQ(bad.exitCode, 2);
    EXPECT_NE(bad.out.find("--tcp-on"), std::string::npos) << bad.out;
}

TEST(PostprocCli, ToolTableGivesToolLengths) {
    test::ScratchDir dir("pp-tooltable");
    test::writeText(dir.file("t.tbl"), "T1 P1 Z0 D1 ;end mill\nT2 P2 Z15 D8 ;end mill\nT10 P10 D0.5\n");
    test::writeText(dir.file("p.ngc"), "G21 G90 G43 H2\nG0 X1 Y0 Z5\n");
    const auto r = test::runCli("poses --in " + dir.file("p.ngc") + " --tool-table " + dir.file("t.tbl"));
    ASSERT_EQ(r.exitCode, 0) << r.out;
    EXPECT_NE(r.out.find("2,G0,1.000000,0.000000,20.000000"), std::string::npos) << r.out;
    // A tool table with a byte-order mark in front of its first line reads as without.
    test::writeText(dir.file("bom.tbl"), "\xEF\xBB\xBFT1 P1 Z0 D1 ;end mill\nT2 P2 Z15 D8 ;end mill\n");
    const auto bom = test::runCli("poses --in " + dir.file("p.ngc") + " --tool-table " + dir.file("bom.tbl"));
    ASSERT_EQ(bom.exitCode, 0) << bom.out;
    EXPECT_EQ(bom.out, r.out);
    test::writeText(dir.file("bad.tbl"), "T1 P1 Z0\nT2 P2 Zfifteen\n");
    const auto bad = test::runCli("poses --in " + dir.file("p.ngc") + " --tool-table " + dir.file("bad.tbl"));
    EXPECT_EQ(bad.exitCode, 2);
    EXPECT_NE(bad.out.find("bad.tbl:2"), std::string::npos) << bad.out;
}

TEST(PostprocCli, SetupFileGivesOffsetsToolLengthsAndAssumedAxes) {
    test::ScratchDir dir("pp-setup");
    test::writeText(dir.file("setup.txt"),
                    "# machine setup\nwork-offset G54=10,0,0\ntool-length H1=100\nassume Y=0\nunits mm\n");
    test::writeText(dir.file("p.nc"), "G54 G43 H1\nG0 X1 Z5\n");
    const auto r = test::runCli("poses --in " + dir.file("p.nc") + " --machine " + kMachine + " --setup " + dir.file("setup.txt"));
    ASSERT_EQ(r.exitCode, 0) << r.out;
    EXPECT_NE(r.out.find("2,G0,11.000000,0.000000,105.000000,,0.000000,0.000000"), std::string::npos) << r.out;
    // The same file saved as "UTF-8 with BOM" (Notepad) reads the same; before, its first key was refused.
    test::writeText(dir.file("bom.txt"), "\xEF\xBB\xBFwork-offset G54=10,0,0\ntool-length H1=100\nassume Y=0\n");
    const auto bom = test::runCli("poses --in " + dir.file("p.nc") + " --machine " + kMachine + " --setup " + dir.file("bom.txt"));
    ASSERT_EQ(bom.exitCode, 0) << bom.out;
    EXPECT_NE(bom.out.find("2,G0,11.000000,0.000000,105.000000,,0.000000,0.000000"), std::string::npos) << bom.out;
    test::writeText(dir.file("bad.txt"), "work-offset G54=10,0,0\ntool-lenght H1=100\n");
    const auto bad = test::runCli("poses --in " + dir.file("p.nc") + " --setup " + dir.file("bad.txt"));
    EXPECT_EQ(bad.exitCode, 2);
    EXPECT_NE(bad.out.find("bad.txt:2"), std::string::npos) << bad.out;
}

TEST(PostprocCli, ChangedWordsKeepTheProgramsNumberStyle) {
    const MachineModel& m = test::multitasking();
    const DeviationSet d = readDeviationCsv(kTruth, m);
    CorrectOptions o;
    o.setup.addToolLength("100");
    o.dialect = Dialect::Fanuc;
    // Fanuc integers (0.001 mm), trimmed decimals with a bare fraction, and a fixed-width program.
    std::istringstream in("G21 G90 G0 X20000 Y-5000 Z50000 B0 C0\nG1 X.5 Y-.25 Z45. F100.\n");
    std::ostringstream out;
    correctProgram(m, d, in, out, o);
    std::istringstream lines(out.str());
    std::string l1, l2;
    std::getline(lines, l1);
    std::getline(lines, l2);
    EXPECT_EQ(l1.rfind("G21 G90 G0 X1997", 0), 0u) << l1;  // 20000 − 30 increments, still an integer
    EXPECT_EQ(l1.find('.'), std::string::npos) << l1;
    EXPECT_NE(l2.find("X.4"), std::string::npos) << l2;     // bare fraction kept
    EXPECT_NE(l2.find("Y-.2"), std::string::npos) << l2;
    o.dialect = Dialect::Rs274ngc;
    std::istringstream fixed("G21 G90 G0 X20.000000 Y-5.000000 Z50.000000 B0 C0\n");
    std::ostringstream out2;
    correctProgram(m, d, fixed, out2, o);
    EXPECT_NE(out2.str().find("X19.9"), std::string::npos) << out2.str();
    EXPECT_NE(out2.str().find("Z50.00"), std::string::npos) << out2.str();
    EXPECT_EQ(out2.str().find("X19.9") + 10, out2.str().find(' ', out2.str().find("X19.9")))
        << "six decimals as the program: " << out2.str();
}

TEST(PostprocCli, TipOnlyLeavesRotaryWordsAlone) {
    test::ScratchDir dir("pp-tiponly");
    const std::string in = test::sourcePath("samples/gcode/multitasking-5axis.ngc");
    const auto r = test::runCli("correct --machine " + kMachine + " --deviations " + kTruth + " --in " + in + " --out " +
                                dir.file("out.ngc") + " --tool-length H1=100 --tip-only --tol-um 1000");
    ASSERT_EQ(r.exitCode, 0) << r.out;
    EXPECT_NE(r.out.find("0.000 arcsec rotary"), std::string::npos) << r.out;
    // Nothing is split at this tolerance: every original line's B and C words are unchanged.
    const std::string out = test::readText(dir.file("out.ngc"));
    std::istringstream a(test::readText(in));
    std::string la;
    size_t checked = 0, pos = 0;
    while (std::getline(a, la)) {
        const size_t pb = la.find(" B");
        if (pb == std::string::npos) continue;
        const size_t found = out.find(la.substr(pb), pos);
        ASSERT_NE(found, std::string::npos) << la;
        pos = found;
        ++checked;
    }
    EXPECT_GT(checked, 80u);
}

}  // namespace
}  // namespace cnccomp::postproc
