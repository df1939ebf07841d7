// Modal interpretation of G-code blocks against hand-computed machine positions: distance and unit modes,
// work offsets, tool length, arcs in three planes (I/J/K and R), lathe diameter mode, Fanuc integer
// increments, rotary shortest path, and the blocks that must pass through (expressions, cycles, calls …).
#include <gtest/gtest.h>

#include <sstream>
#include <string>
#include <vector>

#include "postproc/modal.hpp"
#include "postproc/poses.hpp"
#include "test_support.hpp"

namespace cnccomp::postproc {
namespace {

struct ProgramRun {
    std::vector<BlockResult> blocks;  // one per line
    std::vector<std::string> lines;
};

ProgramRun interpretProgram(const std::string& program, Dialect d = Dialect::Rs274ngc, postproc::Setup setup = {},
                     AxisLayout layout = AxisLayout::generic(), bool shortest = false) {
    Interpreter interp(layout, InterpreterOptions{d, setup, shortest});
    ProgramRun run;
    std::istringstream in(program);
    std::string line;
    LexedBlock b;
    while (std::getline(in, line)) {
        run.lines.push_back(line);
        BlockResult r;
        lexBlock(run.lines.back(), d, b);
        interp.interpret(run.lines.back(), b, r);
        run.blocks.push_back(r);
    }
    return run;
}

constexpr int X = 0, Y = 1, Z = 2, A = 3, B = 4, C = 5;

TEST(PostprocModal, AbsoluteIncrementalUnitsAndOffsets) {
    postproc::Setup s;
    s.addWorkOffset("G54=100,-50,10");
    s.addWorkOffset("G55=0,0,0,0,0,90");
    const ProgramRun r = interpretProgram(
        "G21 G90 G54\n"
        "G0 X1 Y2 Z3\n"
        "G91 G1 X1 Y-1 F100\n"
        "G20 G90 X1\n"
        "G55 G21 C10\n"
        "G0 X0 Y0 Z0\n",
        Dialect::Rs274ngc, s);
    ASSERT_EQ(r.blocks[1].kind, BlockKind::Move);
    EXPECT_NEAR(r.blocks[1].end[X], 101, 1e-12);
    EXPECT_NEAR(r.blocks[1].end[Y], -48, 1e-12);
    EXPECT_NEAR(r.blocks[1].end[Z], 13, 1e-12);
    EXPECT_EQ(r.blocks[1].motion, Motion::Rapid);
    ASSERT_EQ(r.blocks[2].kind, BlockKind::Move);
    EXPECT_NEAR(r.blocks[2].end[X], 102, 1e-12);
    EXPECT_NEAR(r.blocks[2].end[Y], -49, 1e-12);
    EXPECT_EQ(r.blocks[2].motion, Motion::Linear);
    // G20: one inch, plus the (mm) work offset; the other axes keep their machine positions.
    EXPECT_NEAR(r.blocks[3].end[X], 125.4, 1e-12);
    EXPECT_NEAR(r.blocks[3].end[Y], -49, 1e-12);
    // G55 rotates nothing but offsets C by 90 deg: C10 → 100 deg.
    EXPECT_NEAR(r.blocks[4].end[C], 100 * kDeg, 1e-12);
    EXPECT_NEAR(r.blocks[5].end[X], 0, 1e-12);
}

TEST(PostprocModal, ToolLengthOffsetShiftsZAndSetsTheToolPoint) {
    postproc::Setup s;
    s.addToolLength("H3=120.5");
    s.addToolLength("40");
    const ProgramRun r = interpretProgram("G21 G90\nG0 X0 Y0 Z10\nG43 H3 Z10\nG49 Z10\nG43 H9 Z10\n", Dialect::Rs274ngc, s);
    EXPECT_NEAR(r.blocks[1].end[Z], 10, 1e-12);
    EXPECT_NEAR(r.blocks[1].tipLength, 40, 1e-12);
    EXPECT_NEAR(r.blocks[2].end[Z], 130.5, 1e-12);
    EXPECT_NEAR(r.blocks[2].tipLength, 120.5, 1e-12);
    EXPECT_NEAR(r.blocks[3].end[Z], 10, 1e-12);
    // Unknown register: the default length, with a warning.
    EXPECT_NEAR(r.blocks[4].end[Z], 50, 1e-12);
    ASSERT_EQ(r.blocks[4].warningCount, 1);
    EXPECT_EQ(r.blocks[4].warnings[0].first, Warning::ToolLengthNotGiven);
    EXPECT_EQ(r.blocks[4].warnings[0].second, 9);
}

TEST(PostprocModal, ArcsInThreePlanesWithCentreAndRadiusForms) {
    const ProgramRun r = interpretProgram(
        "G21 G90 G17\n"
        "G0 X10 Y0 Z0\n"
        "G3 X0 Y10 I-10 J0\n"          // quarter circle CCW about the origin
        "G2 X10 Y0 R10\n"              // back CW, ≤ 180°: centre on the right of the chord
        "G2 X10 Y0 I-10 J0 Z-3\n"      // full helical turn
        "G18 G2 X0 Z7 I-10 K0\n"       // ZX plane: start (z=-3,x=10), centre (z=-3,x=0)
        "G19 G3 Y0 Z0 R-5\n"           // YZ plane, R < 0: more than 180°
        "G90.1 G17 G2 X0 Y10 I0 J5\n");  // absolute centre (start at the origin)
    ASSERT_EQ(r.blocks[2].kind, BlockKind::Move);
    EXPECT_NEAR(r.blocks[2].arc.c0, 0, 1e-12);
    EXPECT_NEAR(r.blocks[2].arc.c1, 0, 1e-12);
    EXPECT_NEAR(r.blocks[2].arc.sweep, kPi / 2, 1e-12);
    EXPECT_EQ(r.blocks[2].arc.axis0, X);
    EXPECT_EQ(r.blocks[2].arc.normal, Z);
    ASSERT_EQ(r.blocks[3].kind, BlockKind::Move);
    EXPECT_TRUE(r.blocks[3].arc.radiusForm);
    EXPECT_NEAR(r.blocks[3].arc.c0, 0, 1e-9);  // chord (0,10)→(10,0); right of it (clockwise) is the origin
    EXPECT_NEAR(r.blocks[3].arc.c1, 0, 1e-9);
    EXPECT_NEAR(r.blocks[3].arc.sweep, -kPi / 2, 1e-9);
    ASSERT_EQ(r.blocks[4].kind, BlockKind::Move);
    EXPECT_NEAR(r.blocks[4].arc.sweep, -2 * kPi, 1e-12);
    EXPECT_NEAR(r.blocks[4].end[Z], -3, 1e-12);
    ASSERT_EQ(r.blocks[5].kind, BlockKind::Move);
    EXPECT_EQ(r.blocks[5].arc.axis0, Z);
    EXPECT_EQ(r.blocks[5].arc.axis1, X);
    EXPECT_NEAR(r.blocks[5].arc.c0, -3, 1e-12);  // K0 → z = -3
    EXPECT_NEAR(r.blocks[5].arc.c1, 0, 1e-12);   // I-10 → x = 0
    ASSERT_EQ(r.blocks[6].kind, BlockKind::Move);
    EXPECT_GT(std::fabs(r.blocks[6].arc.sweep), kPi);
    EXPECT_LT(std::fabs(r.blocks[6].arc.sweep), 2 * kPi);
    ASSERT_EQ(r.blocks[7].kind, BlockKind::Move) << r.blocks[7].reason;
    EXPECT_NEAR(r.blocks[7].arc.c0, 0, 1e-12);
    EXPECT_NEAR(r.blocks[7].arc.c1, 5, 1e-12);
    EXPECT_NEAR(r.blocks[7].arc.sweep, -kPi, 1e-12);
}

TEST(PostprocModal, ArcsThatAControllerWouldRejectPassThrough) {
    const ProgramRun r = interpretProgram("G0 X0 Y0 Z0\nG2 X10 Y0 I1 J0\nG2 X40 Y0 R5\nG2 X0 Y0 R5\n");
    for (int i = 1; i <= 3; ++i) {
        EXPECT_EQ(r.blocks[i].kind, BlockKind::PassThrough) << r.lines[i];
        EXPECT_TRUE(r.blocks[i].report);
    }
}

TEST(PostprocModal, LatheDiameterModeAndFanucIncrements) {
    const ProgramRun lathe = interpretProgram("G18 G7\nG0 X40 Y0 Z2\nG8\nG1 X40\n");
    EXPECT_NEAR(lathe.blocks[1].end[X], 20, 1e-12);
    EXPECT_NEAR(lathe.blocks[3].end[X], 40, 1e-12);
    const ProgramRun fanuc = interpretProgram("G21 G90\nG0 X20000 Y-5. Z1 A0 B0 C90000\nG20\nX10000\n", Dialect::Fanuc);
    EXPECT_NEAR(fanuc.blocks[1].end[X], 20, 1e-12);
    EXPECT_NEAR(fanuc.blocks[1].end[Y], -5, 1e-12);
    EXPECT_NEAR(fanuc.blocks[1].end[Z], 0.001, 1e-15);
    EXPECT_NEAR(fanuc.blocks[1].end[C], 90 * kDeg, 1e-12);
    EXPECT_NEAR(fanuc.blocks[3].end[X], 25.4, 1e-12);  // 10000 × 0.0001 inch
}

TEST(PostprocModal, RotaryShortestPathOnModuloAxes) {
    const MachineModel& m = test::multitasking();
    const AxisLayout layout = AxisLayout::fromMachine(m);
    const int c = layout.axis('C');
    const ProgramRun r = interpretProgram("G0 X0 Y0 Z100 B0 C350\nC10\nC200\n", Dialect::Rs274ngc, {}, layout, true);
    EXPECT_NEAR(r.blocks[0].end[c], -10 * kDeg, 1e-12);   // from 0: −10 deg, not +350 deg
    EXPECT_NEAR(r.blocks[1].end[c], 10 * kDeg, 1e-12);    // +20 deg
    EXPECT_NEAR(r.blocks[2].end[c], -160 * kDeg, 1e-12);  // 10 → 200 the short way: −170 deg
    const ProgramRun literal = interpretProgram("G0 X0 Y0 Z100 B0 C350\nC10\n", Dialect::Rs274ngc, {}, layout, false);
    EXPECT_NEAR(literal.blocks[0].end[c], 350 * kDeg, 1e-12);
    EXPECT_NEAR(literal.blocks[1].end[c], 10 * kDeg, 1e-12);
}

TEST(PostprocModal, OffsetsFromTheProgram) {
    postproc::Setup s;
    s.addWorkOffset("G54=10,0,0");
    const ProgramRun r = interpretProgram(
        "G90 G54 G0 X0 Y0 Z0\n"
        "G10 L2 P1 X50\n"    // G54 X becomes 50 mm
        "G0 X1\n"
        "G52 X5\n"           // local offset on top
        "G0 X1\n"
        "G92 X0\n"           // position-dependent: cannot be followed
        "G0 X1\n"
        "G92.1\n"
        "G0 X1\n",
        Dialect::Rs274ngc, s);
    EXPECT_NEAR(r.blocks[0].end[X], 10, 1e-12);
    EXPECT_EQ(r.blocks[1].kind, BlockKind::NoMotion);
    EXPECT_NEAR(r.blocks[2].end[X], 51, 1e-12);
    EXPECT_NEAR(r.blocks[4].end[X], 56, 1e-12);
    EXPECT_EQ(r.blocks[5].kind, BlockKind::PassThrough);
    EXPECT_EQ(r.blocks[6].kind, BlockKind::PassThrough);
    EXPECT_EQ(r.blocks[8].kind, BlockKind::Move);
    EXPECT_NEAR(r.blocks[8].end[X], 56, 1e-12);
}

TEST(PostprocModal, WhatCannotBeEvaluatedPassesThroughAndForgetsPositions) {
    const ProgramRun r = interpretProgram(
        "G0 X0 Y0 Z0\n"
        "G1 X[#1+2] Y5 F100\n"   // X unknown, Y = 5 still known
        "G1 Y6\n"                // X not known: pass
        "G1 X1\n"                // everything known again
        "G81 X2 Y2 Z-3 R1\n"     // canned cycle: not corrected, Z unknown after
        "G80\n"
        "G0 X0 Y0\n"             // Z still unknown
        "G0 Z5\n"
        "G28\n"                  // reference return: everything unknown
        "G0 X1 Y1 Z1\n"
        "o100 call\n"            // subroutine: every axis unknown, rotary ones too
        "G0 X2 Y2 Z2 A0 B0 C0\n"
        "G12.5 X1\n");           // unsupported G code
    EXPECT_EQ(r.blocks[0].kind, BlockKind::Move);
    EXPECT_EQ(r.blocks[1].kind, BlockKind::PassThrough);
    EXPECT_FALSE(r.blocks[1].endKnown & (1u << X));
    EXPECT_TRUE(r.blocks[1].endKnown & (1u << Y));
    EXPECT_EQ(r.blocks[2].kind, BlockKind::PassThrough);
    EXPECT_EQ(r.blocks[3].kind, BlockKind::Move);
    EXPECT_EQ(r.blocks[4].kind, BlockKind::PassThrough);
    EXPECT_EQ(r.blocks[5].kind, BlockKind::NoMotion);
    EXPECT_EQ(r.blocks[6].kind, BlockKind::PassThrough);
    EXPECT_EQ(r.blocks[7].kind, BlockKind::Move);
    EXPECT_EQ(r.blocks[8].kind, BlockKind::PassThrough);
    EXPECT_FALSE(r.blocks[8].report);  // an ordinary move, not a problem
    EXPECT_EQ(r.blocks[9].kind, BlockKind::Move);
    EXPECT_EQ(r.blocks[10].kind, BlockKind::PassThrough);
    EXPECT_EQ(r.blocks[11].kind, BlockKind::Move);
    EXPECT_EQ(r.blocks[12].kind, BlockKind::PassThrough);
    EXPECT_EQ(r.blocks[12].reasonCode, 125);
}

TEST(PostprocModal, SinumerikKeywordsAndTcp) {
    const ProgramRun r = interpretProgram(
        "N10 G0 X0 Y0 Z0 A0 B0 C0\n"
        "N20 SOFT FFWON\n"
        "N30 MSG(\"HELLO\")\n"
        "N40 TRAORI\n"
        "N50 G1 X1 B10 F100\n"
        "N60 TRAFOOF\n"
        "N70 G1 X1 Y1 Z1 A0 B0 C0\n"
        "N80 CYCLE800(1,\"TC1\",0)\n"
        "N90 G1 X2\n",
        Dialect::Sinumerik);
    EXPECT_EQ(r.blocks[1].kind, BlockKind::NoMotion);
    EXPECT_EQ(r.blocks[2].kind, BlockKind::NoMotion);
    EXPECT_TRUE(r.blocks[3].modeSwitch);
    EXPECT_EQ(r.blocks[3].mode, ProgramMode::TcpAngles);
    EXPECT_EQ(r.blocks[4].kind, BlockKind::Move);  // tool-tip programming: read in TCP mode
    EXPECT_EQ(r.blocks[4].mode, ProgramMode::TcpAngles);
    EXPECT_TRUE(r.blocks[5].modeSwitch);
    EXPECT_EQ(r.blocks[6].kind, BlockKind::Move);
    EXPECT_EQ(r.blocks[6].mode, ProgramMode::Joints);
    EXPECT_EQ(r.blocks[7].kind, BlockKind::PassThrough);
    EXPECT_EQ(r.blocks[8].kind, BlockKind::PassThrough);
}

TEST(PostprocPoses, CsvOfMachinePositionsFollowsTheModalState) {
    postproc::Setup s;
    s.addWorkOffset("G54=100,0,-50");
    PosesOptions o;
    o.setup = s;
    o.dialect = Dialect::Rs274ngc;
    std::istringstream in("G21 G90 G54\nG0 X1 Y2 Z3 A0 B0 C45\n(comment)\nG91 G1 X-1 F10\nG53 G0 Z0\nG1 X[1+1]\n");
    std::ostringstream out;
    const PosesSummary sum = writePoses(AxisLayout::generic(), in, out, o);
    EXPECT_EQ(out.str(),
              "line,motion,X,Y,Z,A,B,C\n"
              "2,G0,101.000000,2.000000,-47.000000,0.000000,0.000000,45.000000\n"
              "4,G1,100.000000,2.000000,-47.000000,0.000000,0.000000,45.000000\n"
              "5,G53,100.000000,2.000000,0.000000,0.000000,0.000000,45.000000\n"
              "6,-,,2.000000,0.000000,0.000000,0.000000,45.000000\n");
    EXPECT_EQ(sum.moves, 2u);
    EXPECT_EQ(sum.rows, 4u);
}

}  // namespace
}  // namespace cnccomp::postproc
