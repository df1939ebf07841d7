// `cnccomp correct` on HEIDENHAIN Klartext programs (postproc/klartext_correct.*), checked with models written here,
// independently of the corrector:
//  - the controller's nominal TCP kinematics (M128 / FUNCTION TCPM on the xyzac table of LinuxCNC's trt sim, the
//    machine of test_postproc_xyzac.hpp): trtfuncs.c's xyzac inverse and forward as transcribed there (rot-points 0,
//    y-offset 20, z-offset 10; the programmed point is the tool tip at the called tool's length);
//  - the erroneous machine: its links composed by hand from README's definition (placement · E_location · motion),
//    also in test_postproc_xyzac.hpp (shared with test_postproc_tcp.cpp);
//  - the programs: read with a small Klartext scanner of this file (L blocks, absolute words, M128/M129, FUNCTION TCPM,
//    FUNCTION RESET TCPM, TOOL CALL with the tool's length), which carries the position across a mode switch itself.
// Outside TCP mode the controller interpolates the joints, in TCP mode the tool tip on a straight line in the workpiece
// frame with the angles linear (PATHCTRL AXIS): the corrected program's tip is compared with the nominal tool-tip path
// at every end point (≤ 0.15 um) and at the midpoint of every output block (≤ the tolerance).
#include <gtest/gtest.h>

#include <cmath>
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <random>
#include <sstream>
#include <vector>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "postproc/correct_program.hpp"
#include "postproc/testprog/test_program.hpp"
#include "test_postproc_xyzac.hpp"
#include "test_support.hpp"

namespace cnccomp::postproc {
using namespace cnccomp::io;
namespace {

namespace xyzac = cnccomp::test::xyzac;

constexpr double kKtTool = 30.0;                         // TOOL CALL 1 Z: tool 1 is 30 mm long

const char* kKtDeviations = cnccomp::test::xyzac::kDeviationCsv;

/// x y z (mm) a c (deg): joints, or in TCP mode the programmed tip and the angles.
struct Pose5 {
    double x = 0, y = 0, z = 0, a = 0, c = 0;
};

// --- The controller's TCP kinematics and the erroneous machine: test_postproc_xyzac.hpp (trtfuncs.c transcribed, the
// links composed by hand), on this file's Pose5.
Pose5 ktTrtInverse(const Pose5& p, double tool) {
    const xyzac::Joints j = xyzac::trtInverse({p.x, p.y, p.z, p.a, p.c}, tool);
    return {j.x, j.y, j.z, j.a, j.c};
}
Pose5 ktTrtForward(const Pose5& j, double tool) {
    const xyzac::World p = xyzac::trtForward({j.x, j.y, j.z, j.a, j.c}, tool);
    return {p.x, p.y, p.z, p.a, p.c};
}
/// The controller (Klartext TCP): the programmed tip at the tool's length is LinuxCNC's world point minus the length.
Pose5 ktTcpToJoints(const Pose5& p, double tool) { return ktTrtInverse({p.x, p.y, p.z + tool, p.a, p.c}, tool); }
Pose5 ktJointsToTcp(const Pose5& j, double tool) {
    Pose5 w = ktTrtForward(j, tool);
    w.z -= tool;
    return w;
}

using KtErrors = xyzac::Errors;
using KtTip = xyzac::ToolTip;
KtTip ktMachineTip(const Pose5& j, double L, const KtErrors* e) { return xyzac::machineTip({j.x, j.y, j.z, j.a, j.c}, L, e); }

// --- A Klartext scanner ---------------------------------------------------------------------------------------------
struct KtMove {
    long line = 0;
    bool tcp = false;
    bool rapid = false;
    double tool = kKtTool;  // the called tool's length + DL (the physical tool too)
    Pose5 from, to;  // joints at the start and the end
    Pose5 progFrom, progTo;  // program space of the move's mode
    bool arc = false;        // C about the pole (cx, cy) in the XY plane, `sweep` rad (DR+ positive)
    double cx = 0, cy = 0, sweep = 0;
    /// Joints at fraction t: the joints linear, or (TCP) the programmed tip and the angles linear; on a C block X and Y
    /// on the circle.
    Pose5 at(double t) const {
        const Pose5& a = tcp ? progFrom : from;
        const Pose5& b = tcp ? progTo : to;
        Pose5 p{a.x + t * (b.x - a.x), a.y + t * (b.y - a.y), a.z + t * (b.z - a.z), a.a + t * (b.a - a.a),
                a.c + t * (b.c - a.c)};
        if (arc) {
            const double r = std::hypot(a.x - cx, a.y - cy), th = std::atan2(a.y - cy, a.x - cx) + t * sweep;
            p.x = cx + r * std::cos(th);
            p.y = cy + r * std::sin(th);
        }
        return tcp ? ktTcpToJoints(p, tool) : p;
    }
};

double ktWord(const std::string& t, size_t p) { return std::stod(t.substr(p)); }

/// Every L block with X Y Z A C: the tool is 30 mm (TOOL CALL 1), machine Z = word + 30 outside TCP mode.
std::vector<KtMove> ktScan(const std::string& program) {
    std::vector<KtMove> out;
    std::istringstream in(program);
    std::string s;
    long line = 0;
    bool tcp = false;
    Pose5 joints;   // where the machine is
    Pose5 prog;     // program space of the current mode
    double tool = 0;
    double poleX = 0, poleY = 0;
    while (std::getline(in, s)) {
        ++line;
        if (!s.empty() && s.back() == '\r') s.pop_back();
        const size_t semi = s.find(';');
        if (semi != std::string::npos) s.resize(semi);
        std::istringstream words(s);
        std::vector<std::string> tok;
        for (std::string w; words >> w;) tok.push_back(w);
        size_t k = 0;
        if (k < tok.size() && std::isdigit(static_cast<unsigned char>(tok[k][0]))) ++k;
        if (k >= tok.size()) continue;
        auto toProg = [&](bool on) {  // the machine stays, the numbers change their meaning
            if (on) prog = ktJointsToTcp({joints.x, joints.y, joints.z, joints.a, joints.c}, tool);
            else prog = {joints.x, joints.y, joints.z - tool, joints.a, joints.c};
        };
        if (tok[k] == "TOOL" && k + 2 < tok.size()) {
            tool = tok[k + 2] == "1" ? kKtTool : 0.0;
            for (size_t i = k + 3; i < tok.size(); ++i)
                if (tok[i].rfind("DL", 0) == 0) tool += ktWord(tok[i], 2);
            continue;
        }
        if (tok[k] == "FUNCTION") {
            if (k + 1 < tok.size() && tok[k + 1] == "TCPM") tcp = true, toProg(true);
            if (k + 1 < tok.size() && tok[k + 1] == "RESET") tcp = false, toProg(false);
            continue;
        }
        bool m128 = false, m129 = false, any = false, rapid = false;
        for (size_t i = k; i < tok.size(); ++i) {
            if (tok[i] == "M128") m128 = true;
            if (tok[i] == "M129") m129 = true;
            if (tok[i] == "FMAX") rapid = true;
        }
        if (m128 && !tcp) tcp = true, toProg(true);
        if (tok[k] == "CC") {
            for (size_t i = k + 1; i < tok.size(); ++i) {
                if (tok[i][0] == 'X') poleX = ktWord(tok[i], 1);
                if (tok[i][0] == 'Y') poleY = ktWord(tok[i], 1);
            }
            continue;
        }
        if (tok[k] == "L" || tok[k] == "C") {
            KtMove mv;
            mv.line = line;
            mv.tcp = tcp;
            mv.rapid = rapid;
            mv.tool = tool;
            mv.from = joints;
            mv.progFrom = prog;
            for (size_t i = k + 1; i < tok.size(); ++i) {
                const std::string& t = tok[i];
                if (t.size() > 2 && t[0] == 'I') {  // incremental word
                    const double v = ktWord(t, 2);
                    switch (t[1]) {
                        case 'X': prog.x += v, any = true; break;
                        case 'Y': prog.y += v, any = true; break;
                        case 'Z': prog.z += v, any = true; break;
                        case 'A': prog.a += v, any = true; break;
                        case 'C': prog.c += v, any = true; break;
                        default: break;
                    }
                    continue;
                }
                switch (t[0]) {
                    case 'X': prog.x = ktWord(t, 1), any = true; break;
                    case 'Y': prog.y = ktWord(t, 1), any = true; break;
                    case 'Z': prog.z = ktWord(t, 1), any = true; break;
                    case 'A': prog.a = ktWord(t, 1), any = true; break;
                    case 'C': prog.c = ktWord(t, 1), any = true; break;
                    default: break;
                }
            }
            if (any && tok[k] == "C") {
                mv.arc = true;
                mv.cx = poleX, mv.cy = poleY;
                const bool ccw = std::find(tok.begin(), tok.end(), "DR+") != tok.end();
                double sw = std::atan2(prog.y - poleY, prog.x - poleX) - std::atan2(mv.progFrom.y - poleY, mv.progFrom.x - poleX);
                if (ccw) {
                    while (sw <= 1e-12) sw += 2 * kPi;
                } else {
                    while (sw >= -1e-12) sw -= 2 * kPi;
                }
                mv.sweep = sw;
            }
            if (any) {
                joints = tcp ? ktTcpToJoints(prog, tool) : Pose5{prog.x, prog.y, prog.z + tool, prog.a, prog.c};
                mv.to = joints;
                mv.progTo = prog;
                if (!tcp) mv.progFrom.z += tool, mv.progTo.z += tool, mv.from = mv.progFrom, mv.to = mv.progTo;
                out.push_back(mv);
            }
        }
        if (m129 && tcp) tcp = false, toProg(false);
    }
    return out;
}

struct KtCheck {
    double maxEnd = 0, maxMid = 0, maxAxisArcsec = 0, uncorrected = 0, lastEnd = 0;
    size_t inputMoves = 0, outputMoves = 0, tcpMoves = 0;
};

double ktDistanceToPath(const KtMove& m, const Vec3& p) {
    return xyzac::distanceToPath([&](double t) { return ktMachineTip(m.at(t), m.tool, nullptr).tip; }, p);
}

/// The corrected program on the erroneous machine against the original on the nominal one.
KtCheck ktCheck(const std::string& original, const std::string& corrected, const KtErrors& e) {
    const std::vector<KtMove> nom = ktScan(original), act = ktScan(corrected);
    KtCheck c;
    c.inputMoves = nom.size();
    c.outputMoves = act.size();
    size_t s = 0;
    for (size_t k = 1; k < act.size(); ++k) {
        const KtMove& b = act[k];
        if (b.tcp) ++c.tcpMoves;
        const KtTip end = ktMachineTip(b.to, b.tool, &e);
        double bestWorst = HUGE_VAL, bestEnd = 0, bestMid = 0;
        size_t bestIndex = s;
        for (size_t cand = std::max<size_t>(s, 1); cand < std::min(nom.size(), s + 4); ++cand) {
            const double dEnd = ktDistanceToPath(nom[cand], end.tip);
            const double dMid = b.rapid ? 0.0 : ktDistanceToPath(nom[cand], ktMachineTip(b.at(0.5), b.tool, &e).tip);
            if (std::max(dEnd, dMid) < bestWorst - 1e-12) bestWorst = std::max(dEnd, dMid), bestIndex = cand, bestEnd = dEnd, bestMid = dMid;
            if (bestWorst <= 0.2 * kUm) break;
        }
        c.maxEnd = std::max(c.maxEnd, bestEnd);
        c.maxMid = std::max(c.maxMid, bestMid);
        s = bestIndex;
    }
    // End points of the input moves: the corrected program reaches each with the tool axis of the nominal one.
    size_t j = 0;
    for (size_t k = 1; k < nom.size(); ++k) {
        const KtTip n = ktMachineTip(nom[k].to, nom[k].tool, nullptr);
        c.uncorrected = std::max(c.uncorrected, (n.tip - ktMachineTip(nom[k].to, nom[k].tool, &e).tip).norm());
        for (; j < act.size(); ++j) {
            const KtTip a = ktMachineTip(act[j].to, act[j].tool, &e);
            if ((a.tip - n.tip).norm() < 1 * kUm) {
                if (std::fabs(nom[k].to.a) >= 10)
                    c.maxAxisArcsec = std::max(c.maxAxisArcsec, std::acos(std::clamp(a.axis.dot(n.axis), -1.0, 1.0)) / kArcsec);
                break;
            }
        }
    }
    if (!act.empty() && !nom.empty())
        c.lastEnd = (ktMachineTip(act.back().to, act.back().tool, &e).tip - ktMachineTip(nom.back().to, nom.back().tool, nullptr).tip).norm();
    return c;
}

struct KtFiles {
    test::ScratchDir dir{"pp-klartext-correct"};
    std::string machine, deviations;
    KtFiles() {
        machine = dir.file("xyzac-trt.xml");
        deviations = dir.file("deviations.csv");
        test::writeText(machine, test::kXyzacTrtMachine);
        test::writeText(deviations, kKtDeviations);
    }
};

std::string ktCorrect(const std::string& program, CorrectSummary& s, bool zero = false, int decimals = -1, double tolUm = 0.5,
                      int threads = 1) {
    static const KtFiles files;
    const MachineModel m = readMachineXml(files.machine);
    const DeviationSet d = zero ? DeviationSet(m) : readDeviationCsv(files.deviations, m);
    CorrectOptions o;
    o.setup.toolLengths.emplace_back(1, kKtTool);
    o.corrector.toleranceMm = tolUm * kUm;
    o.decimals = decimals;
    o.threads = threads;
    o.inputName = "test.h";
    std::istringstream in(program);
    std::ostringstream out;
    s = correctProgram(m, d, in, out, o);
    return out.str();
}

/// The first `count` moves of LinuxCNC's impeller demo (TCP, X Y Z A C with three decimals) as Klartext L blocks.
std::vector<std::string> ktImpellerBlocks(size_t count) {
    const std::string path = test::sharedPath("gcode-corpus/impeller-7bl-xyzac.ngc");
    std::vector<std::string> out;
    if (!std::filesystem::exists(path)) return out;
    std::istringstream in(test::readText(path));
    std::string s;
    while (std::getline(in, s) && out.size() < count) {
        if (s.rfind("G0", 0) != 0 && s.rfind("G1", 0) != 0) continue;
        std::istringstream w(s);
        std::string g, letter, value, block = "L";
        w >> g;
        std::string feed;
        while (w >> letter >> value) {
            if (letter == "F") feed = value;
            else block += " " + letter + (value[0] == '-' ? value : "+" + value);
        }
        block += g == "G0" ? " R0 FMAX" : " R0 F" + feed;
        out.push_back(block);
    }
    return out;
}

std::string ktNumbered(const std::vector<std::string>& blocks, const std::string& eol = "\n") {
    std::string t;
    long n = 0;
    for (const std::string& b : blocks) t += (b.empty() || b[0] == ';' || b[0] == '*' ? b : fmt::format("{} {}", n++, b)) + eol;
    return t;
}

void ktPrint(const char* what, const KtCheck& c, const CorrectSummary& s) {
    std::printf("[ klartext ] %-26s moves %zu -> %zu (TCP %zu), end points %.4f um, midpoints %.4f um (uncorrected %.2f um), "
                "tool axis %.3f arcsec, split %llu (+%llu blocks)\n",
                what, c.inputMoves, c.outputMoves, c.tcpMoves, c.maxEnd / kUm, c.maxMid / kUm, c.uncorrected / kUm,
                c.maxAxisArcsec, static_cast<unsigned long long>(s.split), static_cast<unsigned long long>(s.addedLines));
}

// --- 1. Identity ----------------------------------------------------------------------------------------------------
TEST(PostprocKlartextCorrect, ZeroDeviationsKeepEveryByte) {
    // testprog's Klartext programs of two sample plans (circles as CC / C blocks, chords, cycles 7 and 9, STOP).
    for (const auto& [machine, plan] : {std::pair{"table-table-ac", "dbb5-table-table-ac"}, std::pair{"multitasking", "multitasking-six-circles"}}) {
        const MachineModel& m = test::sampleMachine(machine);
        postproc::testprog::TestProgramOptions o;
        o.dialect = postproc::Dialect::Heidenhain;
        for (const auto& p : postproc::testprog::makeTestPrograms(m, readPlanXml(test::sourcePath(fmt::format("samples/plans/{}.xml", plan))), o).programs) {
            CorrectOptions co;
            co.setup.defaultToolLength = 100;
            std::istringstream in(p.text);
            std::ostringstream out;
            const CorrectSummary s = correctProgram(m, DeviationSet(m), in, out, co);
            EXPECT_TRUE(out.str() == p.text) << p.file;
            EXPECT_GT(s.moves, 30u);
        }
    }
    std::vector<std::string> programs;
    const std::string hand =
        "; hand written\n0 BEGIN PGM HAND MM\n1 BLK FORM 0.1 Z X+0 Y+0 Z-40\n2 TOOL CALL 1 Z S3000 DL+0.02\n"
        "* - roughing\n3 L Z+100 R0 FMAX M3\n4 L  X+10   Y-5.50 A+0 C+0 R0 FMAX ; two spaces\n5 L IX+5 IY-2.5 Z+50 RL F200\n"
        "6 CC X+25 Y+25\n7 L X+45 Y+25 RR F200\n8 C X+45 Y+25 DR+\n9 CR X+20 Y+0 R+20 DR-\n10 LP PR+10 PA+45\n"
        "11 CYCL DEF 200 DRILLING ~\n    Q200=+2 ;SET-UP CLEARANCE ~\n    Q201=-20 ;DEPTH\n12 L X+1 Y+2 Z+3 R0 FMAX M99\n"
        "13 LBL 1\n14 L X+Q1 R0 F100\n15 M128\n16 L X+1 Y+2 Z+3 A-20 C+10 F500\n17 L Z+50 M129\n"
        "18 FUNCTION TCPM F TCP AXIS POS PATHCTRL AXIS\n19 L X+2 A-25\n20 FUNCTION RESET TCPM\n21 PLANE SPATIAL SPA+0 SPB+45 SPC+0 TURN FMAX\n"
        "22 L X+3\n23 END PGM HAND MM";
    programs.push_back(hand);
    std::string crlf;
    for (char ch : hand) crlf += ch == '\n' ? std::string("\r\n") : std::string(1, ch);
    programs.push_back(crlf + "\r\n");
    const auto imp = ktImpellerBlocks(300);
    if (!imp.empty()) {
        std::vector<std::string> blocks{"BEGIN PGM IMP MM", "TOOL CALL 1 Z", "M128"};
        blocks.insert(blocks.end(), imp.begin(), imp.end());
        blocks.push_back("M129");
        blocks.push_back("END PGM IMP MM");
        programs.push_back(ktNumbered(blocks, "\r\n"));
    }
    for (const std::string& p : programs) {
        CorrectSummary s;
        const std::string out = ktCorrect(p, s, true);
        EXPECT_TRUE(out == p) << p.substr(0, 200);
        EXPECT_EQ(s.dialect, Dialect::Heidenhain);
        EXPECT_GT(s.moves, 0u);
        EXPECT_EQ(s.corrected, 0u);
    }
}

// --- 2. Joint mode --------------------------------------------------------------------------------------------------
TEST(PostprocKlartextCorrect, JointModeProgramPutsTheTipOnTheNominalPath) {
    // The impeller's numbers read as machine positions (no TCPM): a joint-space path of 1000 moves.
    const auto imp = ktImpellerBlocks(1000);
    if (imp.empty()) GTEST_SKIP() << "no impeller program in ../shared/gcode-corpus";
    // Tool 1 with DL+0.5 (the tip is 30.5 mm from the spindle); every third block in incremental words.
    std::vector<std::string> blocks{"BEGIN PGM JOINTS MM", "TOOL CALL 1 Z S600 DL+0.5"};
    blocks.insert(blocks.end(), imp.begin(), imp.end());
    blocks.push_back("END PGM JOINTS MM");
    {
        const std::vector<KtMove> abs = ktScan(ktNumbered(blocks));
        for (size_t k = 3; k < blocks.size() - 1; k += 3) {
            const KtMove& m = abs[k - 2];  // block k is move k − 2 (BEGIN PGM and TOOL CALL first)
            const double d[5] = {m.progTo.x - m.progFrom.x, m.progTo.y - m.progFrom.y, m.progTo.z - m.progFrom.z,
                                 m.progTo.a - m.progFrom.a, m.progTo.c - m.progFrom.c};
            std::string b = "L";
            for (int i = 0; i < 5; ++i) b += fmt::format(" I{}{:+.3f}", "XYZAC"[i], d[i]);
            blocks[k] = b + (m.rapid ? " R0 FMAX" : " R0 F159");
        }
    }
    const std::string program = ktNumbered(blocks);
    CorrectSummary s;
    const std::string out = ktCorrect(program, s, false, 6, 0.5);
    const KtCheck c = ktCheck(program, out, KtErrors{});
    ktPrint("impeller as joint moves", c, s);
    EXPECT_EQ(c.tcpMoves, 0u);
    EXPECT_EQ(s.tcpMoves, 0u);
    EXPECT_GE(c.inputMoves, 1000u);
    EXPECT_GT(c.uncorrected, 10 * kUm) << "the deviations must matter";
    EXPECT_LE(c.maxEnd, 0.15 * kUm);
    EXPECT_LE(c.lastEnd, 0.15 * kUm);
    EXPECT_LE(c.maxMid, 0.5 * kUm);
    EXPECT_LE(c.maxAxisArcsec, 0.6);
    EXPECT_EQ(s.unconverged, 0u);
    EXPECT_EQ(s.passedThrough, 0u) << formatSummary(s);
    EXPECT_EQ(s.moves, 1000u);
    EXPECT_NE(out.find(" IX"), std::string::npos);
    // Read back in TCP mode (as if M128 were active) the same words are wrong by far more than the tolerance.
    const KtCheck wrong = ktCheck("0 M128\n" + program, "0 M128\n" + out, KtErrors{});
    EXPECT_GT(wrong.maxEnd, 5 * kUm);
}

// --- 3. TCP mode ----------------------------------------------------------------------------------------------------
void ktExpectTcp(const char* what, const std::string& on, const std::string& off, size_t count) {
    const auto imp = ktImpellerBlocks(count);
    if (imp.empty()) GTEST_SKIP() << "no impeller program in ../shared/gcode-corpus";
    // Tool 1 with DL+0.5: the programmed point is the tip 30.5 mm from the spindle, for the controller's inverse too
    // (on this table machine the tool stays vertical: a length the corrector and the controller share does not move
    // the tip; DL itself is checked by the reader's tests, tests/postproc/testprog/test_testprog_klartext.cpp).
    std::vector<std::string> blocks{"BEGIN PGM TCP MM", "TOOL CALL 1 Z S600 DL+0.5", on};
    blocks.insert(blocks.end(), imp.begin(), imp.end());
    blocks.push_back(off);
    blocks.push_back("END PGM TCP MM");
    const std::string program = ktNumbered(blocks);
    CorrectSummary s;
    const std::string out = ktCorrect(program, s);  // the program's own decimals: 3 → 4
    const KtCheck c = ktCheck(program, out, KtErrors{});
    ktPrint(what, c, s);
    EXPECT_EQ(s.tcpMoves, s.moves) << formatSummary(s);
    EXPECT_EQ(s.moves, count);
    EXPECT_EQ(c.tcpMoves + 1, c.outputMoves);
    EXPECT_GT(c.uncorrected, 10 * kUm) << "the deviations must matter";
    EXPECT_LE(c.maxEnd, 0.15 * kUm);
    EXPECT_LE(c.lastEnd, 0.15 * kUm);
    EXPECT_LE(c.maxMid, 0.5 * kUm);
    EXPECT_LE(c.maxAxisArcsec, 0.6);
    EXPECT_EQ(s.unconverged, 0u);
    EXPECT_EQ(s.passedThrough, 0u) << formatSummary(s);
    // The programmed point is the nominal tool tip in the workpiece frame (the chain of models agrees with itself).
    const auto nom = ktScan(program);
    for (size_t k = 0; k < nom.size(); k += 97) {
        const Vec3 tip = ktMachineTip(nom[k].to, nom[k].tool, nullptr).tip;
        EXPECT_NEAR(tip.x(), nom[k].progTo.x, 1e-9);
        EXPECT_NEAR(tip.z(), nom[k].progTo.z, 1e-9);
    }
    // Corrected as joint moves (no TCPM), the same words fail this check.
    std::string joint = program;
    for (const std::string& w : {on, off}) joint.replace(joint.find(w), w.size(), "STOP");
    CorrectSummary sj;
    const std::string wrongOut = ktCorrect(joint, sj);
    const KtCheck wrong = ktCheck(program, std::string(wrongOut).replace(wrongOut.find("STOP"), 4, on), KtErrors{});
    EXPECT_GT(wrong.maxEnd, 5 * kUm);
}

TEST(PostprocKlartextCorrect, M128ProgramCorrectedInTcpMode) { ktExpectTcp("M128 impeller", "M128", "M129", 2000); }

TEST(PostprocKlartextCorrect, FunctionTcpmProgramCorrectedInTcpMode) {
    ktExpectTcp("FUNCTION TCPM impeller", "FUNCTION TCPM F TCP AXIS POS PATHCTRL AXIS", "FUNCTION RESET TCPM", 1000);
}

// --- 4. Mode switching ----------------------------------------------------------------------------------------------
TEST(PostprocKlartextCorrect, ModeSwitchesCorrectEachSectionInItsMode) {
    const auto imp = ktImpellerBlocks(400);
    if (imp.empty()) GTEST_SKIP() << "no impeller program in ../shared/gcode-corpus";
    std::vector<std::string> blocks{"BEGIN PGM SWITCH MM", "TOOL CALL 1 Z"};
    const auto part = [&](size_t from, size_t to) { blocks.insert(blocks.end(), imp.begin() + long(from), imp.begin() + long(to)); };
    part(0, 60);                                   // joints
    blocks.push_back("M128");
    part(60, 140);                                 // TCP
    blocks.push_back(imp[140] + " M129");          // TCP, then off at the end of the block
    part(141, 200);                                // joints
    blocks.push_back("FUNCTION TCPM F TCP AXIS POS PATHCTRL AXIS");
    part(200, 300);                                // TCP
    blocks.push_back("FUNCTION RESET TCPM");
    part(300, 340);                                // joints
    blocks.push_back(imp[340] + " M128");          // TCP from the start of the block
    part(341, 400);
    blocks.push_back("M129");
    blocks.push_back("END PGM SWITCH MM");
    const std::string program = ktNumbered(blocks);
    CorrectSummary s;
    const std::string out = ktCorrect(program, s, false, 6, 0.5);
    const KtCheck c = ktCheck(program, out, KtErrors{});
    ktPrint("M128/M129 + FUNCTION TCPM", c, s);
    EXPECT_EQ(s.moves, 400u);
    EXPECT_EQ(s.tcpMoves, 81u + 100u + 60u);
    EXPECT_EQ(s.passedThrough, 0u) << formatSummary(s);
    EXPECT_GT(c.uncorrected, 10 * kUm);
    EXPECT_LE(c.maxEnd, 0.15 * kUm);
    EXPECT_LE(c.lastEnd, 0.15 * kUm);
    EXPECT_LE(c.maxMid, 0.5 * kUm);
    // Each section on its own: the joint sections read as TCP (or the TCP ones as joints) are off.
    std::string swapped = out;
    for (const auto& [a, b] : {std::pair<std::string, std::string>{"M129", "M128"}}) {
        size_t p = 0;
        while ((p = swapped.find(a, p)) != std::string::npos) swapped.replace(p, a.size(), b), p += b.size();
    }
    EXPECT_GT(ktCheck(program, swapped, KtErrors{}).maxEnd, 5 * kUm);
}

// --- 5. Numbers, line ends, errors ---------------------------------------------------------------------------------
TEST(PostprocKlartextCorrect, CirclesBecomeChordsOnTheNominalCircleInBothModes) {
    // A full circle and a quarter under M128 (the tip on the circle in the workpiece frame, the table tilted and
    // turned), then the same outside TCP mode (the slides on the circle).
    const std::string program =
        "0 BEGIN PGM ARC MM\n1 TOOL CALL 1 Z\n2 L X+20 Y+0 Z+10 A-30 C+20 R0 FMAX\n3 M128\n4 L X+20 Y+0 Z+5 A-30 C+20 R0 F300\n"
        "5 CC X+0 Y+0\n6 C X+20 Y+0 DR+\n7 C X+0 Y-20 DR-\n8 L Z+20 M129\n9 L X+30 Y+10 Z+40 A-30 C+20 R0 F500\n"
        "10 CC X+10 Y+10\n11 C X+10 Y+30 DR+\n12 END PGM ARC MM\n";
    CorrectSummary s;
    const std::string out = ktCorrect(program, s, false, 6, 0.5);
    const KtCheck c = ktCheck(program, out, KtErrors{});
    ktPrint("circles as chords", c, s);
    EXPECT_EQ(s.arcsToLines, 3u);
    EXPECT_EQ(s.tcpMoves, 4u);
    EXPECT_EQ(s.passedThrough, 0u) << formatSummary(s);
    EXPECT_EQ(out.find(" C X"), std::string::npos) << out;
    EXPECT_GT(c.outputMoves, 100u);
    EXPECT_GT(c.uncorrected, 10 * kUm);
    EXPECT_LE(c.maxEnd, 0.15 * kUm);
    EXPECT_LE(c.lastEnd, 0.15 * kUm);
    EXPECT_LE(c.maxMid, 0.5 * kUm);
    EXPECT_NE(out.find("5 CC X+0 Y+0\n"), std::string::npos);
    // Chords read as the circle they replace would not pass: the check sees the circle.
    EXPECT_GT(ktCheck(program, std::string(program).replace(program.find("6 C X+20 Y+0 DR+"), 16, "6 L X+20 Y+0"),
                      KtErrors{}).maxMid, 5 * kUm);
}

TEST(PostprocKlartextCorrect, InsertedBlocksRenumberTheRestAndCrlfStays) {
    // A long joint move across C and A: split; every later block number moves up by the blocks inserted.
    const std::string program =
        "0 BEGIN PGM SPLIT MM\r\n1 TOOL CALL 1 Z\r\n2 L X+10 Y+5 Z+20 A-10 C+0 R0 FMAX\r\n3 L X+40 Y+20 Z+30 A-60 C+90 R0 F500\r\n"
        "4 ; after the split\r\n5 L X+41 R0\r\n6 CC X+41 Y+30\r\n7 C X+41 Y+20 DR+\r\n8 END PGM SPLIT MM\r\n";
    CorrectSummary s;
    const std::string out = ktCorrect(program, s, false, -1, 1.0);
    ASSERT_GT(s.split, 0u) << out;
    EXPECT_EQ(s.arcsToLines, 1u);
    std::istringstream lines(out);
    std::string l;
    long expect = 0;
    size_t count = 0;
    while (std::getline(lines, l)) {
        ASSERT_FALSE(l.empty());
        EXPECT_EQ(l.back(), '\r') << l;  // CRLF kept on every line, the inserted ones too
        const long n = std::stol(l);
        EXPECT_EQ(n, expect) << out;     // consecutive block numbers
        ++expect;
        ++count;
    }
    EXPECT_EQ(count, 9u + s.addedLines);
    EXPECT_NE(out.find(fmt::format("{} END PGM SPLIT MM\r\n", 8 + s.addedLines)), std::string::npos) << out;
    EXPECT_NE(out.find(" ; after the split\r\n"), std::string::npos);
    // Changed words: signed, four decimals (the program has none), F and R0 kept on the original block.
    EXPECT_NE(out.find("3 L X+"), std::string::npos) << out;
    EXPECT_NE(out.find(" R0 F500\r\n"), std::string::npos) << out;
    EXPECT_EQ(out.find(" C X"), std::string::npos) << "the circle is written as straight chords\n" << out;
    // --threads: the same bytes.
    CorrectSummary s2;
    EXPECT_EQ(ktCorrect(program, s2, false, -1, 1.0, 2), out);
}

TEST(PostprocKlartextCorrect, UnsupportedBlocksPassThroughAndMalformedOnesNameTheLine) {
    const std::string head = "0 BEGIN PGM E MM\n1 TOOL CALL 1 Z\n2 L X+0 Y+0 Z+50 A-20 C+0 R0 FMAX\n";
    {
        CorrectSummary s;
        const std::string program = head + "3 L X+Q1 R0 F100\n4 L X+5 Y+5 R0 F100\n5 CYCL CALL\n6 L X+6 R0\n7 L X+1 Y+1 Z+40 R0\n8 END PGM E MM\n";
        const std::string out = ktCorrect(program, s);
        EXPECT_EQ(s.passedThrough, 4u) << formatSummary(s);  // Q (line 4), CYCL CALL, then two moves with axes unknown
        EXPECT_EQ(s.uncorrected(), 4u);
        ASSERT_GE(s.passThrough.size(), 2u);
        EXPECT_EQ(s.passThrough[0].line, 4u);
        EXPECT_NE(s.passThrough[0].message.find("Q parameters"), std::string::npos) << s.passThrough[0].message;
        EXPECT_NE(out.find("3 L X+Q1 R0 F100\n"), std::string::npos);
        EXPECT_NE(out.find("5 CYCL CALL\n"), std::string::npos);
        EXPECT_EQ(s.moves, 2u);  // blocks 2 and 7
    }
    {
        // M91 / M92: machine coordinates, not corrected and not counted by --strict (like G53).
        CorrectSummary s;
        const std::string out = ktCorrect(head + "3 L Z+100 R0 FMAX M91\n4 L X+5 Y+5 Z+40 R0 F100\n5 END PGM E MM\n", s);
        EXPECT_NE(out.find("3 L Z+100 R0 FMAX M91\n"), std::string::npos) << out;
        EXPECT_EQ(s.passedThrough, 1u);
        EXPECT_EQ(s.notCorrected, 1u);
        EXPECT_EQ(s.uncorrected(), 0u);
        EXPECT_EQ(s.moves, 2u);
        EXPECT_EQ(s.corrected, 2u);
    }
    for (const auto& [block, words] : {std::pair<std::string, std::string>{"3 L X+1e R0\n", "not a number"},
                                       {"3 L X+1e3 Y+0 R0\n", "exponent notation"},
                                       {"3 L X+5 Y R0 FMAX\n", "unexpected"},
                                       {"3 C X+5 Y+5 DR+\n", "CC first"},
                                       {"3 BEGIN PGM X CM\n", "MM or INCH"}}) {
        CorrectSummary s;
        try {
            ktCorrect(head + block, s);
            ADD_FAILURE() << "no error for " << block;
        } catch (const InputError& e) {
            EXPECT_EQ(e.line(), 4) << e.what();
            EXPECT_EQ(e.file(), "test.h");
            EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
        }
    }
}

TEST(PostprocKlartextCorrect, DamagedProgramsEndInAnInputErrorOrAnOutputNeverInACrash) {
    // Bytes of a program with every kind of block replaced, inserted or deleted at random: the corrector either writes
    // a program or throws InputError naming test.h and a line of it; nothing else.
    const std::string base =
        "0 BEGIN PGM R MM\n1 TOOL CALL 1 Z S3000 DL+0.02\n2 L X+0 Y+0 Z+50 A-20 C+0 R0 FMAX\n3 CC X+0 Y+25\n"
        "4 C X+25 Y+25 DR+ R0 F200\n5 CR X+20 Y+5 R+20 DR-\n6 CT X+10 Y+10\n7 LP PR+10 IPA+45\n8 CP IPA+720 IZ-5 DR+\n"
        "9 M128\n10 L IX+1 Y+2 Z+30 A-25 C+10 F500\n11 L Z+50 M129\n12 FUNCTION TCPM F TCP AXIS POS PATHCTRL AXIS\n"
        "13 L X+2 A-30\n14 FUNCTION RESET TCPM\n15 CYCL DEF 7.0 DATUM SHIFT\n16 CYCL DEF 7.1 IX+5\n17 L X+3 R0 ~\n"
        "   F100 ; continued\n18 END PGM R MM\n";
    {
        CorrectSummary s;
        ASSERT_NO_THROW(ktCorrect(base, s));
        EXPECT_EQ(s.passedThrough, 0u) << formatSummary(s);
        EXPECT_EQ(s.moves, 10u);
    }
    const std::string alphabet = "0123456789+-. XYZACLRFMIPD~;*\n";
    std::mt19937 rng(7);
    int written = 0, refused = 0;
    for (int trial = 0; trial < 400; ++trial) {
        std::string p = base;
        for (int k = 0; k < 1 + trial % 3; ++k) {
            const size_t at = std::uniform_int_distribution<size_t>(0, p.size() - 1)(rng);
            const char ch = alphabet[std::uniform_int_distribution<size_t>(0, alphabet.size() - 1)(rng)];
            switch (rng() % 3) {
                case 0: p[at] = ch; break;
                case 1: p.insert(p.begin() + long(at), ch); break;
                default: p.erase(at, 1); break;
            }
        }
        CorrectSummary s;
        try {
            ktCorrect(p, s);
            ++written;
        } catch (const InputError& e) {
            EXPECT_EQ(e.file(), "test.h");
            EXPECT_GE(e.line(), 0) << e.what();
            ++refused;
        }
    }
    EXPECT_GT(written, 50);
    EXPECT_GT(refused, 50);
    std::printf("[ klartext ] damaged programs: %d corrected, %d refused with file:line\n", written, refused);
}

TEST(PostprocKlartextCorrect, LinesLongerThanTheBufferPassThroughAndForgetThePosition) {
    const KtFiles files;
    const MachineModel m = readMachineXml(files.machine);
    const DeviationSet d = readDeviationCsv(files.deviations, m);
    const std::string longLine = "4 L X+5 Y+5 R0 F100 ; " + std::string(300, 'x');
    const std::string program = "0 BEGIN PGM O MM\n1 TOOL CALL 1 Z\n2 L X+0 Y+0 Z+50 A-20 C+0 R0 FMAX\n3 L X+1 Y+1 Z+40 ~\n"
                                "  A-21 C+1 R0 F100\n" + longLine + "\n5 L X+2 R0\n6 L X+3 Y+3 Z+45 A-20 C+0\n7 END PGM O MM\n";
    for (const bool zero : {true, false}) {
        CorrectOptions o;
        o.setup.toolLengths.emplace_back(1, kKtTool);
        o.bufferSize = 128;
        std::istringstream in(program);
        std::ostringstream out;
        const CorrectSummary s = correctProgram(m, zero ? DeviationSet(m) : d, in, out, o);
        if (zero) {
            EXPECT_EQ(out.str(), program);
        }
        EXPECT_NE(out.str().find(longLine + "\n"), std::string::npos);
        EXPECT_EQ(s.lines, 9u);
        EXPECT_EQ(s.passedThrough, 2u) << formatSummary(s);  // the long line, then block 5 (Y Z A C unknown)
        EXPECT_EQ(s.moves, 3u);                               // blocks 2, 3 (two lines) and 6
        ASSERT_FALSE(s.passThrough.empty());
        EXPECT_NE(s.passThrough[0].message.find("longer than 128 bytes"), std::string::npos) << s.passThrough[0].message;
    }
}

TEST(PostprocKlartextCorrect, CliStrictExitsThreeAndAMalformedBlockWritesNothing) {
    test::ScratchDir dir("pp-klartext-cli");
    const std::string m = test::sourcePath("samples/machines/table-table-ac.xml");
    const std::string d = test::sourcePath("samples/deviations/table-table-ac-truth.csv");
    const std::string p = dir.file("part.h"), o = dir.file("out.h");
    const std::string good = "0 BEGIN PGM PART MM\n1 TOOL CALL 1 Z S3000\n2 L X+10 Y+20 Z+50 A+30 C+0 R0 FMAX\n3 L X+15 F500\n";
    test::writeText(p, good + "4 END PGM PART MM\n");
    auto r = test::runCli("correct --machine " + m + " --deviations " + d + " --in " + p + " --out " + o +
                          " --tool-length 100 --strict");
    EXPECT_EQ(r.exitCode, 0) << r.out;
    EXPECT_NE(r.out.find("dialect: heidenhain"), std::string::npos) << r.out;
    EXPECT_NE(test::readText(o), test::readText(p));
    test::writeText(p, good + "4 LBL 1\n5 END PGM PART MM\n");
    r = test::runCli("correct --machine " + m + " --deviations " + d + " --in " + p + " --out " + o + " --tool-length 100 --strict");
    EXPECT_EQ(r.exitCode, 3) << r.out;
    EXPECT_NE(r.out.find("line 5: LBL"), std::string::npos) << r.out;
    std::filesystem::remove(o);
    test::writeText(p, good + "4 L X+1..2 R0\n5 END PGM PART MM\n");
    r = test::runCli("correct --machine " + m + " --deviations " + d + " --in " + p + " --out " + o + " --tool-length 100");
    EXPECT_EQ(r.exitCode, 2) << r.out;
    EXPECT_NE(r.out.find("part.h:5"), std::string::npos) << r.out;
    EXPECT_FALSE(std::filesystem::exists(o));  // no half file
}

}  // namespace
}  // namespace cnccomp::postproc
