// The Klartext reader of `cnccomp poses` (postproc/klartext_reader.hpp) on hand-written HEIDENHAIN programs. The
// expected endpoints are worked out by hand from the TNC 640 Klartext manual's definitions (independent of the code):
// the manual's full-circle example (CC X+25 Y+25, L X+45 Y+25, C X+45 Y+25 DR+), CR/CT/LP/CP, datum shift, tool length.
#include <gtest/gtest.h>

#include <sstream>

#include "cnccomp/error.hpp"
#include "postproc/dialect.hpp"
#include "postproc/klartext_reader.hpp"
#include "test_support.hpp"

namespace cnccomp {
namespace {

struct Row {
    long line;
    std::string motion;
    std::string cells[6];
};

std::vector<Row> poses(const std::string& program, postproc::Setup setup = {}) {
    postproc::PosesOptions o;
    o.dialect = postproc::Dialect::Heidenhain;
    o.setup = std::move(setup);
    o.inputName = "test.h";
    std::istringstream in(program);
    std::ostringstream csv;
    postproc::writePoses(postproc::AxisLayout::generic(), in, csv, o);
    std::vector<Row> rows;
    std::istringstream lines(csv.str());
    std::string l;
    std::getline(lines, l);
    EXPECT_EQ(l, "line,motion,X,Y,Z,A,B,C");
    while (std::getline(lines, l)) {
        Row r;
        std::stringstream s(l);
        std::string cell;
        std::getline(s, cell, ',');
        r.line = std::stol(cell);
        std::getline(s, r.motion, ',');
        for (auto& c : r.cells) std::getline(s, c, ',');
        rows.push_back(r);
    }
    return rows;
}

double cell(const Row& r, char axis) { return std::stod(r.cells[std::string("XYZABC").find(axis)]); }

void expectError(const std::string& program, int line, const std::string& words) {
    try {
        poses(program);
        FAIL() << "no error for:\n" << program;
    } catch (const InputError& e) {
        EXPECT_EQ(e.line(), line) << e.what();
        EXPECT_EQ(e.file(), "test.h");
        EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
}

TEST(Klartext, DetectedFromBeginPgmAndDispatchedByPoses) {
    EXPECT_EQ(postproc::detectDialect("0 BEGIN PGM ABC MM\n1 L X+0 R0 FMAX\n").dialect, postproc::Dialect::Heidenhain);
    EXPECT_EQ(postproc::detectDialect("(BEGIN PGM in a comment)\nG0 X1\n").dialect, postproc::Dialect::Rs274ngc);
    test::ScratchDir dir("klartext-cli");
    test::writeText(dir.file("p.h"), "0 BEGIN PGM P MM\n1 L X+10 Y-5 Z+100 R0 FMAX\n2 END PGM P MM\n");
    const auto r = test::runCli("poses --in " + dir.file("p.h"));
    ASSERT_EQ(r.exitCode, 0) << r.out;
    EXPECT_NE(r.out.find("2,G0,10.000000,-5.000000,100.000000,0.000000,0.000000,0.000000"), std::string::npos) << r.out;
}

TEST(Klartext, StraightMovesAbsoluteIncrementalRapidAndFeed) {
    const auto rows = poses(
        "0 BEGIN PGM T MM\n"
        "1 BLK FORM 0.1 Z X+0 Y+0 Z-40\n"
        "2 TOOL CALL 0 Z S1000\n"
        "3 L Z+100 R0 FMAX M3 ; comment\n"
        "4 L X+10 Y+20 R0 FMAX\n"
        "5 L IX+5 IY-2.5 Z+50 RL F200\n"
        "* - structure\n"
        "6 L B+30 C-45 F100\n"
        "7 L M30\n"
        "8 END PGM T MM\n");
    ASSERT_EQ(rows.size(), 4u);
    EXPECT_EQ(rows[0].motion, "-");  // X and Y not known yet
    EXPECT_EQ(rows[0].cells[2], "100.000000");
    EXPECT_EQ(rows[1].motion, "G0");
    EXPECT_EQ(rows[2].motion, "G1");
    EXPECT_EQ(rows[2].line, 6);
    EXPECT_DOUBLE_EQ(cell(rows[2], 'X'), 15.0);
    EXPECT_DOUBLE_EQ(cell(rows[2], 'Y'), 17.5);
    EXPECT_DOUBLE_EQ(cell(rows[2], 'Z'), 50.0);
    EXPECT_DOUBLE_EQ(cell(rows[3], 'B'), 30.0);
    EXPECT_DOUBLE_EQ(cell(rows[3], 'C'), -45.0);
}

TEST(Klartext, ManualsFullCircleAndArcDirections) {
    // TNC 640 manual, "Circular path C around circle center CC": full circle from (45, 25) about (25, 25).
    auto rows = poses(
        "0 BEGIN PGM C MM\n1 L X+0 Y+0 Z+0 R0 FMAX\n2 CC X+25 Y+25\n3 L X+45 Y+25 RR F200 M3\n4 C X+45 Y+25 DR+\n"
        "5 C X+25 Y+45 DR+\n6 C X+45 Y+25 DR-\n7 END PGM C MM\n");
    ASSERT_EQ(rows.size(), 5u);
    EXPECT_EQ(rows[2].motion, "G3");  // DR+: counter-clockwise; a full circle ends where it starts
    EXPECT_DOUBLE_EQ(cell(rows[2], 'X'), 45.0);
    EXPECT_DOUBLE_EQ(cell(rows[2], 'Y'), 25.0);
    EXPECT_EQ(rows[3].motion, "G3");
    EXPECT_DOUBLE_EQ(cell(rows[3], 'X'), 25.0);
    EXPECT_DOUBLE_EQ(cell(rows[3], 'Y'), 45.0);
    EXPECT_EQ(rows[4].motion, "G2");
    // End point off the circle by more than the input tolerance (0.016 mm).
    expectError("0 BEGIN PGM C MM\n1 L X+0 Y+0 Z+0 R0 FMAX\n2 CC X+25 Y+25\n3 C X+25 Y+26 DR+\n", 4, "off the circle");
    expectError("0 BEGIN PGM C MM\n1 L X+0 Y+0 Z+0 R0 FMAX\n2 C X+25 Y+26 DR+\n", 3, "CC first");
    expectError("0 BEGIN PGM C MM\n1 L X+0 Y+0 Z+0 R0 FMAX\n2 CC X+0 Y+10\n3 C X+10 Y+10\n", 4, "DR+ or DR-");
}

TEST(Klartext, CircleInTheZxPlaneFromTheAxesOfCc) {
    // CC Z X: circle about Z = 50, X = 0 starting at X = 10, Z = 50. Counter-clockwise seen from +Y runs from +Z towards
    // +X: the start sits at 90° (on +X) and a quarter turn DR+ ends at 180°, Z = 40, X = 0.
    const auto rows = poses("0 BEGIN PGM Z MM\n1 L X+10 Y+0 Z+50 R0 FMAX\n2 CC Z+50 X+0\n3 C Z+40 X+0 DR+\n4 END PGM Z MM\n");
    ASSERT_EQ(rows.size(), 2u);
    EXPECT_EQ(rows[1].motion, "G3");
    EXPECT_DOUBLE_EQ(cell(rows[1], 'Z'), 40.0);
    EXPECT_DOUBLE_EQ(cell(rows[1], 'X'), 0.0);
}

TEST(Klartext, RadiusTangentialAndPolarBlocks) {
    auto rows = poses(
        "0 BEGIN PGM R MM\n"
        "1 L X+0 Y+0 Z+0 R0 FMAX\n"
        "2 CR X+20 Y+0 R+10 DR-\n"    // half circle of radius 10 about (10, 0)
        "3 L X+20 Y+10 F100\n"         // up along +Y
        "4 CT X+30 Y+20\n"            // tangential: leaves along +Y, ends at (30, 20): centre (30, 10), clockwise
        "5 CC X+0 Y+0\n"
        "6 LP PR+50 PA+90\n"          // (0, 50)
        "7 CP IPA+90 DR+\n"           // (−50, 0)
        "8 LP IPR-10 IPA-45 F200\n"   // radius 40 at 135°
        "9 END PGM R MM\n");
    ASSERT_EQ(rows.size(), 7u);
    EXPECT_EQ(rows[1].motion, "G2");
    EXPECT_DOUBLE_EQ(cell(rows[1], 'X'), 20.0);
    EXPECT_EQ(rows[3].motion, "G2");
    EXPECT_DOUBLE_EQ(cell(rows[3], 'X'), 30.0);
    EXPECT_DOUBLE_EQ(cell(rows[3], 'Y'), 20.0);
    EXPECT_NEAR(cell(rows[4], 'X'), 0.0, 1e-6);
    EXPECT_NEAR(cell(rows[4], 'Y'), 50.0, 1e-6);
    EXPECT_EQ(rows[5].motion, "G3");
    EXPECT_NEAR(cell(rows[5], 'X'), -50.0, 1e-6);
    EXPECT_NEAR(cell(rows[5], 'Y'), 0.0, 1e-6);
    EXPECT_NEAR(cell(rows[6], 'X'), -40.0 / std::sqrt(2.0), 1e-6);
    EXPECT_NEAR(cell(rows[6], 'Y'), 40.0 / std::sqrt(2.0), 1e-6);
    expectError("0 BEGIN PGM R MM\n1 TOOL CALL 0 Z\n2 CT X+10 Y+0\n", 3, "preceding contour element");
    expectError("0 BEGIN PGM R MM\n1 L X+0 Y+0 Z+0 R0 FMAX\n2 CR X+30 Y+0 R+10 DR+\n", 3, "smaller than half");
}

TEST(Klartext, ToolLengthDatumShiftMachineCoordinatesAndInch) {
    postproc::Setup setup;
    setup.toolLengths.emplace_back(3, 120.0);
    const auto rows = poses(
        "0 BEGIN PGM D MM\n"
        "1 TOOL CALL 3 Z S2000 DL+0.5\n"
        "2 CYCL DEF 7.0 DATUM SHIFT\n"
        "3 CYCL DEF 7.1 X+100\n"
        "4 CYCL DEF 7.2 IY+20\n"
        "5 L X+1 Y+2 Z+3 R0 FMAX\n"
        "6 L Z+500 R0 FMAX M91\n"
        "7 CYCL DEF 9.0 DWELL TIME\n"
        "8 CYCL DEF 9.1 DWELL 1.5\n"
        "9 STOP\n"
        "10 END PGM D MM\n",
        setup);
    ASSERT_EQ(rows.size(), 2u);
    EXPECT_DOUBLE_EQ(cell(rows[0], 'X'), 101.0);
    EXPECT_DOUBLE_EQ(cell(rows[0], 'Y'), 22.0);
    EXPECT_DOUBLE_EQ(cell(rows[0], 'Z'), 3.0 + 120.5);  // the tool length and DL shift the tool axis
    EXPECT_EQ(rows[1].motion, "G53");
    EXPECT_DOUBLE_EQ(cell(rows[1], 'Z'), 500.0);
    const auto inch = poses("0 BEGIN PGM I INCH\n1 L X+1 Y+2 Z+0.5 C+90 R0 FMAX\n2 END PGM I INCH\n");
    EXPECT_DOUBLE_EQ(cell(inch[0], 'X'), 25.4);
    EXPECT_DOUBLE_EQ(cell(inch[0], 'C'), 90.0);
}

TEST(Klartext, SubprogramsCyclesAndParametersAreRefusedNamingTheLine) {
    const std::string head = "0 BEGIN PGM E MM\n1 L X+0 Y+0 Z+0 R0 FMAX\n";
    expectError(head + "2 LBL 1\n", 3, "LBL");
    expectError(head + "2 CALL LBL 1 REP 2\n", 3, "CALL LBL");
    expectError(head + "2 CALL PGM SUB\n", 3, "CALL PGM");
    expectError(head + "2 L X+Q1 R0 FMAX\n", 3, "Q parameters");
    expectError(head + "2 FN 0: Q1 = +5\n", 3, "FN");
    expectError(head + "2 CYCL DEF 200 DRILLING\n3 CYCL CALL\n", 4, "CYCL CALL");
    expectError(head + "2 CYCL DEF 10.0 ROTATION\n", 3, "cycle 10");
    expectError(head + "2 PLANE SPATIAL SPA+0 SPB+45 SPC+0 TURN FMAX\n", 3, "PLANE");
    expectError(head + "2 L X+5 R0 FMAX M99\n", 3, "M99");
    expectError(head + "2 L X+5 Y R0 FMAX\n", 3, "unexpected");
    expectError(head + "2 RND R5\n", 3, "RND");
    expectError(head + "2 L X+1e R0\n", 3, "not a number");
}

TEST(Klartext, MultiLineCycleDefinitionsAreOneBlock) {
    const auto rows = poses(
        "0 BEGIN PGM M MM\n1 L X+0 Y+0 Z+10 R0 FMAX\n"
        "2 CYCL DEF 200 DRILLING ~\n    Q200=+2 ;SET-UP CLEARANCE ~\n    Q201=-20 ;DEPTH\n"
        "3 L X+5 R0 FMAX\n4 END PGM M MM\n");
    ASSERT_EQ(rows.size(), 2u);
    EXPECT_EQ(rows[1].line, 6);
}

}  // namespace
}  // namespace cnccomp
