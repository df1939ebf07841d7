// Accuracy of corrected programs, checked independently of the corrector: the corrected program is read back,
// every move of it is run through the erroneous machine (Kinematics(m, d)), and the tool tip at every endpoint
// and every segment midpoint must lie within 0.5 um of the nominal path — the input program run through the
// nominal machine — found by a closest-point search along the nominal moves.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "cnccomp/kinematics.hpp"
#include "postproc/correct_program.hpp"
#include "test_support.hpp"

namespace cnccomp::postproc {
using namespace cnccomp::io;
namespace {

struct PathMove {
    bool arc = false, rapid = false;
    AxisVector a, b;
    ArcGeometry g;
    double tipLength = 0;
    int line = 0;
};

/// Evaluated moves of a program, as the controller's modal semantics define them.
std::vector<PathMove> movesOf(const std::string& program, const MachineModel& m, const CorrectOptions& o) {
    const AxisLayout layout = AxisLayout::fromMachine(m);
    Interpreter interp(layout, InterpreterOptions{*o.dialect, o.setup, o.rotaryShortest});
    std::vector<PathMove> moves;
    std::istringstream in(program);
    std::string line;
    LexedBlock b;
    BlockResult r;
    int no = 0;
    while (std::getline(in, line)) {
        ++no;
        if (!line.empty() && line.back() == '\r') line.pop_back();
        lexBlock(line, *o.dialect, b, no == 1);
        interp.interpret(line, b, r);
        if (r.kind != BlockKind::Move) continue;
        PathMove mv;
        mv.arc = r.motion == Motion::ArcCw || r.motion == Motion::ArcCcw;
        mv.rapid = r.motion == Motion::Rapid;
        mv.a = r.start;
        mv.b = r.end;
        mv.g = r.arc;
        mv.tipLength = r.tipLength;
        mv.line = no;
        moves.push_back(mv);
    }
    return moves;
}

/// Commands at parameter t: straight in every axis, or the RS274NGC circle/spiral in the plane axes.
AxisVector at(const PathMove& mv, double t) {
    AxisVector q = mv.a + t * (mv.b - mv.a);
    if (!mv.arc) return q;
    const int i = mv.g.axis0, j = mv.g.axis1;
    const double r0 = std::hypot(mv.a[i] - mv.g.c0, mv.a[j] - mv.g.c1);
    const double r1 = std::hypot(mv.b[i] - mv.g.c0, mv.b[j] - mv.g.c1);
    const double th = std::atan2(mv.a[j] - mv.g.c1, mv.a[i] - mv.g.c0) + t * mv.g.sweep;
    q[i] = mv.g.c0 + (r0 + t * (r1 - r0)) * std::cos(th);
    q[j] = mv.g.c1 + (r0 + t * (r1 - r0)) * std::sin(th);
    return q;
}

Vec3 tipOf(const Kinematics& k, const PathMove& mv, double t) {
    return k.toolPointInWorkpiece(at(mv, t), k.toolPoint(mv.tipLength));
}

/// The nominal tip path of one input move, sampled densely once; closest points are refined on the exact path.
struct NominalPath {
    const PathMove* move = nullptr;
    std::vector<Vec3> samples;
};

NominalPath sampleMove(const Kinematics& nominal, const PathMove& mv) {
    NominalPath p;
    p.move = &mv;
    const int n = 64 + static_cast<int>(std::fabs(mv.g.sweep) * 40);
    p.samples.reserve(n + 1);
    for (int k = 0; k <= n; ++k) p.samples.push_back(tipOf(nominal, mv, double(k) / n));
    return p;
}

/// Closest distance from q to the nominal tip path: nearest dense sample, then golden-section search on the exact
/// path between its neighbours.
double distanceToMove(const Kinematics& nominal, const NominalPath& path, const Vec3& q) {
    const int n = static_cast<int>(path.samples.size()) - 1;
    int best = 0;
    double bestD = HUGE_VAL;
    for (int k = 0; k <= n; ++k) {
        const double d = (path.samples[k] - q).squaredNorm();
        if (d < bestD) bestD = d, best = k;
    }
    const double phi = (std::sqrt(5.0) - 1) / 2;
    double lo = std::max(0.0, (best - 1.0) / n), hi = std::min(1.0, (best + 1.0) / n);
    double m1 = hi - phi * (hi - lo), m2 = lo + phi * (hi - lo);
    double f1 = (tipOf(nominal, *path.move, m1) - q).norm(), f2 = (tipOf(nominal, *path.move, m2) - q).norm();
    for (int it = 0; it < 32; ++it) {
        if (f1 < f2) {
            hi = m2, m2 = m1, f2 = f1;
            m1 = hi - phi * (hi - lo);
            f1 = (tipOf(nominal, *path.move, m1) - q).norm();
        } else {
            lo = m1, m1 = m2, f1 = f2;
            m2 = lo + phi * (hi - lo);
            f2 = (tipOf(nominal, *path.move, m2) - q).norm();
        }
    }
    return std::min({std::sqrt(bestD), f1, f2});
}

struct Check {
    double maxDeviation = 0;   // corrected program through the erroneous machine, mm
    double uncorrected = 0;    // original program through the erroneous machine, mm (shows the test can fail)
    size_t points = 0, inputMoves = 0, outputMoves = 0;
};

/// Walks the output moves in order; each one must sit on one of the next few input moves.
Check check(const std::vector<PathMove>& nominalMoves, const std::vector<PathMove>& actualMoves, const Kinematics& nominal,
            const Kinematics& actual) {
    Check c;
    c.inputMoves = nominalMoves.size();
    c.outputMoves = actualMoves.size();
    std::vector<NominalPath> paths;
    paths.reserve(nominalMoves.size());
    for (const PathMove& mv : nominalMoves) paths.push_back(sampleMove(nominal, mv));
    size_t s = 0;
    for (const PathMove& mv : actualMoves) {
        double bestWorst = HUGE_VAL;
        size_t bestIndex = s;
        for (size_t cand = s; cand < std::min(nominalMoves.size(), s + 4); ++cand) {
            double worst = 0;
            for (double t : {0.5, 1.0}) {
                if (t == 0.5 && mv.rapid) continue;  // a rapid's path is the controller's business
                worst = std::max(worst, distanceToMove(nominal, paths[cand], tipOf(actual, mv, t)));
            }
            if (worst < bestWorst - 1e-12) bestWorst = worst, bestIndex = cand;
            if (worst <= 0.5 * kUm) break;  // on the nominal path: no need to look further along it
        }
        c.maxDeviation = std::max(c.maxDeviation, bestWorst);
        c.points += mv.rapid ? 1 : 2;
        s = bestIndex;
    }
    return c;
}

struct Case {
    const char* program;
    const char* machine;
    const char* deviations;
    std::vector<std::string> toolLengths;
    std::vector<std::string> offsets;
};

Check runCase(const Case& cs, double tolUm, int decimals, CorrectSummary* summary = nullptr, std::string* output = nullptr,
              bool verify = true) {
    const MachineModel m = readMachineXml(test::sourcePath(std::string("samples/machines/") + cs.machine));
    const DeviationSet d = readDeviationCsv(test::sourcePath(std::string("samples/deviations/") + cs.deviations), m);
    CorrectOptions o;
    o.dialect = Dialect::Rs274ngc;
    for (const auto& t : cs.toolLengths) o.setup.addToolLength(t);
    for (const auto& w : cs.offsets) o.setup.addWorkOffset(w);
    o.corrector.toleranceMm = tolUm * kUm;
    o.decimals = decimals;
    const std::string programPath = std::string(cs.program).find('/') == std::string::npos
                                        ? test::sourcePath(std::string("samples/gcode/") + cs.program)
                                        : std::string(cs.program);
    const std::string input = test::readText(programPath);
    std::istringstream in(input);
    std::ostringstream out;
    const CorrectSummary s = correctProgram(m, d, in, out, o);
    if (summary) *summary = s;
    if (output) *output = out.str();
    if (!verify) return {};
    const Kinematics nominal(m), actual(m, d);
    const auto nominalMoves = movesOf(input, m, o);
    Check c = check(nominalMoves, movesOf(out.str(), m, o), nominal, actual);
    c.uncorrected = check(nominalMoves, nominalMoves, nominal, actual).maxDeviation;
    return c;
}

const Case kFiveAxis{"multitasking-5axis.ngc", "multitasking.xml", "multitasking-truth.csv", {"H1=100"}, {"G54=0,0,0"}};
const Case kMillTurn{"mill-turn.ngc", "multitasking.xml", "multitasking-truth.csv", {"60", "H2=100"}, {"G54=0,0,0"}};
const Case kTableTable{"table-table-ac-5axis.ngc", "table-table-ac.xml", "postproc-table-table.csv", {"120"}, {}};

void expectAccurate(const Case& cs) {
    CorrectSummary s;
    const Check c = runCase(cs, 0.5, 6, &s);
    ::testing::Test::RecordProperty(std::string(cs.program) + "_max_deviation_um", std::to_string(c.maxDeviation / kUm));
    std::printf("[ accuracy ] %-26s moves %zu -> %zu, %zu points checked, max %.4f um (uncorrected %.2f um), "
                "split %llu, arcs->lines %llu\n",
                cs.program, c.inputMoves, c.outputMoves, c.points, c.maxDeviation / kUm, c.uncorrected / kUm,
                static_cast<unsigned long long>(s.split), static_cast<unsigned long long>(s.arcsToLines));
    EXPECT_GT(c.uncorrected, 5 * kUm) << "the deviations must matter, or this test proves nothing";
    EXPECT_LE(c.maxDeviation, 0.5 * kUm) << cs.program;
    EXPECT_GE(c.outputMoves, c.inputMoves);
    EXPECT_EQ(s.unconverged, 0u);
    // The residual measured before the solver's last step (<= 1e-6 mm, its tolerance): well below 0.01 um.
    EXPECT_LT(s.maxTipResidual, 2e-3 * kUm);
}

TEST(PostprocAccuracy, FiveAxisMultitaskingProgram) { expectAccurate(kFiveAxis); }
TEST(PostprocAccuracy, MillTurnProgram) { expectAccurate(kMillTurn); }
TEST(PostprocAccuracy, TableTableFiveAxisProgram) { expectAccurate(kTableTable); }

TEST(PostprocAccuracy, CorpusArcSpiralInInchWithRadiusArcs) {
    // A real program: 1000 G2 R-arcs in inch (read in place from the shared corpus).
    const std::string path = test::sharedPath("gcode-corpus/arcspiral.ngc");
    if (!std::filesystem::exists(path)) GTEST_SKIP() << "no " << path;
    const Case spiral{path.c_str(), "multitasking.xml", "multitasking-truth.csv", {"100"}, {"G54=0,0,0"}};
    CorrectSummary s;
    const Check c = runCase(spiral, 0.5, 7, &s);
    std::printf("[ accuracy ] arcspiral.ngc (corpus)     moves %zu -> %zu, max %.4f um (uncorrected %.2f um), arcs->lines %llu\n",
                c.inputMoves, c.outputMoves, c.maxDeviation / kUm, c.uncorrected / kUm,
                static_cast<unsigned long long>(s.arcsToLines));
    EXPECT_GE(c.inputMoves, 1000u);
    EXPECT_GT(c.uncorrected, 5 * kUm);
    EXPECT_LE(c.maxDeviation, 0.5 * kUm);
}

TEST(PostprocAccuracy, ProgramDecimalsWithATighterToleranceStillMeetHalfAMicron) {
    // Default number formatting (the program's decimals, at least 4): rounding adds at most ~0.15 um here.
    const Check c = runCase(kMillTurn, 0.3, -1);
    EXPECT_LE(c.maxDeviation, 0.5 * kUm);
}

TEST(PostprocAccuracy, SplitsOnlyWhereNeededAndKeepsTheProgramsText) {
    CorrectSummary loose, tight;
    std::string out;
    runCase(kFiveAxis, 20.0, 6, &loose, nullptr, false);
    runCase(kFiveAxis, 0.5, 6, &tight, &out, false);
    EXPECT_LT(loose.addedLines, tight.addedLines);
    EXPECT_GT(tight.split, 0u);
    // Comments and N numbers stay where they were; added lines carry no N number.
    const std::string in = test::readText(test::sourcePath("samples/gcode/multitasking-5axis.ngc"));
    std::istringstream a(in), b(out);
    std::string la, lb;
    size_t nIn = 0, nOut = 0, comments = 0;
    while (std::getline(a, la)) nIn += la.rfind("N", 0) == 0, comments += la.rfind("(", 0) == 0;
    size_t commentsOut = 0;
    while (std::getline(b, lb)) nOut += lb.rfind("N", 0) == 0, commentsOut += lb.rfind("(", 0) == 0;
    EXPECT_EQ(nIn, nOut);
    EXPECT_EQ(comments, commentsOut);
}

TEST(PostprocAccuracy, InverseTimeFeedsOfSplitMovesKeepTheMoveTime) {
    // A long G93 move with rotary motion is split; the pieces' times (1/F) must add up to the original time.
    const std::string program =
        "G21 G90 G17\nG0 X40 Y0 Z10 B0 C0\nG93 G1 X-40 Y10 Z20 B40 C300 F2.5\nG94\n";
    const MachineModel& m = test::multitasking();
    const DeviationSet d = readDeviationCsv(test::sourcePath("samples/deviations/multitasking-truth.csv"), m);
    CorrectOptions o;
    o.dialect = Dialect::Rs274ngc;
    o.setup.addToolLength("100");
    o.decimals = 6;
    std::istringstream in(program);
    std::ostringstream out;
    const CorrectSummary s = correctProgram(m, d, in, out, o);
    ASSERT_EQ(s.split, 1u);
    std::istringstream lines(out.str());
    std::string line;
    double minutes = 0;
    int pieces = 0;
    while (std::getline(lines, line)) {
        const size_t f = line.find('F');
        if (f == std::string::npos || (line.find("G93") == std::string::npos && line.rfind("G1 ", 0) != 0)) continue;
        minutes += 1.0 / std::stod(line.substr(f + 1));
        ++pieces;
    }
    EXPECT_EQ(pieces, static_cast<int>(s.addedLines) + 1);
    EXPECT_NEAR(minutes, 1.0 / 2.5, 1e-5);
}

TEST(PostprocAccuracy, CorrectedArcsStayArcsWhenTheyCan) {
    // A small arc on a machine with squareness errors only: the corrected arc stays a G2 with a new centre.
    const std::string program = "G21 G90 G17\nG0 X5 Y0 Z10 B0 C0\nG1 Z0 F100\nG2 X0 Y-5 I-5 J0\nG2 X5 Y0 R-5\n";
    const MachineModel& m = test::multitasking();
    DeviationSet d(m);
    d.setLinkValue("EC0Y", 20 * kArcsec);
    d.setLinkValue("EB0Z", -15 * kArcsec);
    CorrectOptions o;
    o.dialect = Dialect::Rs274ngc;
    o.decimals = 6;
    std::istringstream in(program);
    std::ostringstream out;
    const CorrectSummary s = correctProgram(m, d, in, out, o);
    EXPECT_EQ(s.arcsToLines, 0u);
    EXPECT_EQ(s.split, 0u);
    EXPECT_NE(out.str().find("G2 X0 Y-5 I-5 J"), std::string::npos) << out.str();  // a new centre, same arc
    EXPECT_NE(out.str().find("G2 X5 Y-0.000"), std::string::npos) << out.str();
    EXPECT_NE(out.str().find(" R-5"), std::string::npos) << out.str();
    const Kinematics nominal(m), actual(m, d);
    const Check c = check(movesOf(program, m, o), movesOf(out.str(), m, o), nominal, actual);
    EXPECT_LE(c.maxDeviation, 1.0 * kUm);
}

}  // namespace
}  // namespace cnccomp::postproc
