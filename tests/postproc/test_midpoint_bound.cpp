// The midpoint bound (postproc/midpoint_bound.hpp) against the exact check it replaces (Corrector::deviationAt: the
// inverse TCP kinematics of the corrected interpolation, the erroneous machine's tool tip, the nominal path's):
//  - on random straight TCP moves of two table-table machines with random location errors from calibration size to
//    500 times that, rotary steps up to 20 deg, starts rounded as the written digits round them: the bound is never
//    below the exact deviation, and its curvature term is needed (without it the bound fails on some moves: the test
//    can fail);
//  - machines and deviation sets outside its class get no bound;
//  - whole programs (LinuxCNC's impeller demo from ../shared/gcode-corpus, a random TCP program with long rotary moves)
//    corrected with and without it: every output byte and every summary figure the same, most checks settled.
// Oracle kind: the exact evaluation of our own models (the property the bound claims), and our corrector with the
// bound switched off (nothing may change).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <sstream>

#include <fmt/format.h>

#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "postproc/correct_program.hpp"
#include "postproc/correction.hpp"
#include "test_postproc_xyzac.hpp"
#include "test_support.hpp"

namespace cnccomp::postproc {
using namespace cnccomp::io;
namespace {

/// LinuxCNC's xyzac-trt machine; `withComponent`: with a positioning error of X too (a component error).
MachineModel xyzacMachine(bool withComponent = false) {
    test::ScratchDir dir("midpoint-bound-machine");
    std::string xml = test::kXyzacTrtMachine;
    if (withComponent) {
        const size_t at = xml.find("</deviations>");
        xml.insert(at, "<component name=\"EXX\" link=\"X\" component=\"x\" basis=\"polynomial\" order=\"2\"/>\n");
    }
    test::writeText(dir.file("m.xml"), xml);
    return readMachineXml(dir.file("m.xml"));
}

/// Location errors only, each uniform in ±linear mm / ±angular rad.
DeviationSet randomLocationErrors(const MachineModel& m, std::mt19937& rng, double linear, double angular) {
    DeviationSet d(m);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (const DeviationDef& def : m.deviations)
        if (def.kind == DeviationKind::Location) d.values[def.offset] = u(rng) * (def.isAngle() ? angular : linear);
    return d;
}

double roundTo(double v, double step) { return std::round(v / step) * step; }

struct Trials {
    int moves = 0, unconverged = 0, curvatureNeeded = 0;
    double worstRatio = 0;  ///< largest exact / bound
    std::vector<double> ratios;
};

/// Random straight moves on `m` with deviations `d`: each end corrected, the start rounded to the output's digits (4
/// decimals of mm and deg) or moved by up to 1 um, the exact midpoint deviation against the bound.
void runTrials(const MachineModel& m, const DeviationSet& d, std::mt19937& rng, int count, Trials& t) {
    Corrector corrector(m, d);
    const MidpointBound& bound = corrector.midpointBound();
    ASSERT_TRUE(bound.usable()) << m.name;
    const int n = m.axisCount();
    const TcpModel& tcp = corrector.tcp();
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const double rotarySteps[] = {0.01 * kDeg, 0.5 * kDeg, 3 * kDeg, 20 * kDeg};
    const double linearSteps[] = {0.01, 0.5, 5.0};
    for (int trial = 0; trial < count; ++trial) {
        const double L = std::array<double, 3>{0.0, 30.0, 120.0}[trial % 3];
        const double Lc = std::array<double, 3>{0.0, L, 0.5 * L}[(trial / 3) % 3];
        const MoveSpace space{ProgramMode::TcpAngles, Lc, L};
        ProgramPoint ns, ne;
        ns.p = AxisVector::Zero(n);
        for (int k = 0; k < 3; ++k) ns.p[tcp.linearAxis(k)] = 80.0 * u(rng);
        const double rot = rotarySteps[trial % 4], lin = linearSteps[(trial / 4) % 3];
        ne.p = ns.p;
        for (int a = 0; a < n; ++a) {
            const bool rotary = m.axisLink(a).kind == AxisKind::Rotary;
            if (rotary) ns.p[a] = 100.0 * kDeg * u(rng);
            ne.p[a] = ns.p[a] + (rotary ? rot : lin) * u(rng);
        }
        AxisVector c0, c1, cn0, cn1;
        ProgramPoint q0, q1;
        SolveResult s0, s1;
        {
            AxisVector guess = AxisVector::Zero(n);
            if (!corrector.toJoints(space, ns, guess, cn0) || !corrector.toJoints(space, ne, guess, cn1)) continue;
            s0 = corrector.correct(space, ns, cn0, cn0, nullptr, cn0, c0, q0);
            s1 = corrector.correct(space, ne, cn1, cn1, nullptr, cn1, c1, q1);
        }
        if (!s0.converged || !s1.converged || !(s0.tipError < 1e-5) || !(s1.tipError < 1e-5)) {
            ++t.unconverged;
            continue;
        }
        // The written start: the corrected end rounded to the output's digits, or moved by up to 1 um / 1e-5 deg.
        ProgramPoint out = q0;
        for (int a = 0; a < n; ++a) {
            const bool rotary = m.axisLink(a).kind == AxisKind::Rotary;
            if (trial % 2 == 0) out.p[a] = rotary ? roundTo(q0.p[a] / kDeg, 1e-4) * kDeg : roundTo(q0.p[a], 1e-4);
            else out.p[a] += rotary ? 1e-5 * kDeg * u(rng) : 1e-3 * u(rng);
        }
        const double b0 = bound.endBound(s0.tipError, c0, L, corrector.options().solveTolerance);
        const double b1 = bound.endBound(s1.tipError, c1, L, corrector.options().solveTolerance);
        const double U = bound.midpoint(L, Lc, out.p, q1.p, ns.p, ne.p, q0.p, b0, b1);
        PathContext ctx;
        ctx.space = space;
        ctx.outStart = out;
        ctx.guess = c0;
        ProgramPoint pn, pc;
        pn.p = 0.5 * (ns.p + ne.p);
        pc.p = 0.5 * (out.p + q1.p);
        const double dev = corrector.deviationAt(ctx, pn, pc, 0.5);
        ASSERT_TRUE(std::isfinite(dev) && std::isfinite(U));
        ++t.moves;
        const double ratio = dev / U;
        t.ratios.push_back(ratio);
        t.worstRatio = std::max(t.worstRatio, ratio);
        EXPECT_LE(dev, U) << m.name << " trial " << trial << ": exact " << dev / kUm << " um, bound " << U / kUm
                          << " um (L " << L << ", Lc " << Lc << ", rotary step " << rot / kDeg << " deg)";
        if (dev > U - bound.curvatureTerm(L, Lc, out.p, q1.p, ns.p, ne.p)) ++t.curvatureNeeded;
    }
}

TEST(MidpointBound, IsNeverBelowTheExactCheckOnRandomMoves) {
    std::mt19937 rng(20261128);
    const MachineModel xyzac = xyzacMachine();
    const MachineModel bc = readMachineXml(test::sourcePath("samples/machines/table-table-bc-offsets.xml"));
    Trials all;
    for (const MachineModel* m : {&xyzac, &bc}) {
        for (const double scale : {1.0, 20.0, 500.0}) {  // 10 um / 10 arcsec per deviation, and larger
            const DeviationSet d = randomLocationErrors(*m, rng, 0.010 * scale, 10 * kArcsec * scale);
            Trials t;
            runTrials(*m, d, rng, 600, t);
            if (::testing::Test::HasFatalFailure()) return;
            all.moves += t.moves, all.unconverged += t.unconverged, all.curvatureNeeded += t.curvatureNeeded;
            all.worstRatio = std::max(all.worstRatio, t.worstRatio);
            all.ratios.insert(all.ratios.end(), t.ratios.begin(), t.ratios.end());
        }
    }
    std::sort(all.ratios.begin(), all.ratios.end());
    const double median = all.ratios.empty() ? 0.0 : all.ratios[all.ratios.size() / 2];
    std::printf("[midpoint bound] %d moves (%d not converged, left out): exact / bound largest %.3f, median %.3f; "
                "%d moves need the curvature term\n",
                all.moves, all.unconverged, all.worstRatio, median, all.curvatureNeeded);
    EXPECT_GE(all.moves, 3000);
    EXPECT_GT(all.curvatureNeeded, 0) << "no move needs the curvature term: the trials do not test it";
}

TEST(MidpointBound, NoBoundOutsideItsClass) {
    const MachineModel xyzac = xyzacMachine();
    std::mt19937 rng(7);
    // A component error (positioning of X) not zero: the error is no longer rigid. At zero it is.
    const MachineModel comp = xyzacMachine(true);
    DeviationSet dc = randomLocationErrors(comp, rng, 0.01, 1e-4);
    EXPECT_TRUE(Corrector(comp, dc).midpointBound().usable());
    for (const DeviationDef& def : comp.deviations)
        if (def.kind == DeviationKind::Component) dc.values[def.offset] = 1e-3;
    EXPECT_FALSE(Corrector(comp, dc).midpointBound().usable());
    // A tilting head: the tool chain turns.
    const MachineModel head = readMachineXml(test::sourcePath("samples/machines/tilting-head-b.xml"));
    EXPECT_FALSE(Corrector(head, randomLocationErrors(head, rng, 0.01, 1e-4)).midpointBound().usable());
    // Switched off, or nothing to correct.
    CorrectorOptions off;
    off.boundChecks = false;
    EXPECT_FALSE(Corrector(xyzac, randomLocationErrors(xyzac, rng, 0.01, 1e-4), off).midpointBound().usable());
    EXPECT_FALSE(Corrector(xyzac, DeviationSet(xyzac)).midpointBound().usable());
    EXPECT_TRUE(Corrector(xyzac, randomLocationErrors(xyzac, rng, 0.01, 1e-4)).midpointBound().usable());
}

/// The program corrected with the bound and without: the same bytes and summary; returns the summary with the bound.
CorrectSummary sameWithAndWithout(const std::string& program, const MachineModel& m, const DeviationSet& d, double L,
                                  int threads) {
    CorrectSummary with, without;
    std::string outWith, outWithout;
    for (const bool bounded : {true, false}) {
        CorrectOptions o;
        o.dialect = Dialect::Rs274ngc;
        o.setup.addToolLength(std::to_string(L));
        o.tcpOnM = 428, o.tcpOffM = 429;
        o.threads = threads;
        o.corrector.boundChecks = bounded;
        std::istringstream in(program);
        std::ostringstream out;
        (bounded ? with : without) = correctProgram(m, d, in, out, o);
        (bounded ? outWith : outWithout) = out.str();
    }
    EXPECT_TRUE(outWith == outWithout) << "the outputs differ";
    EXPECT_EQ(formatSummary(with, 1000), formatSummary(without, 1000));
    EXPECT_EQ(std::memcmp(&with.maxPathDeviation, &without.maxPathDeviation, sizeof(double)), 0);
    EXPECT_EQ(with.split, without.split);
    EXPECT_EQ(with.limited, without.limited);
    EXPECT_EQ(without.boundedChecks, 0u);
    return with;
}

TEST(MidpointBound, ChangesNoByteOfTheImpellerDemo) {
    const std::string path = test::sharedPath("gcode-corpus/impeller-7bl-xyzac.ngc");
    if (!std::filesystem::exists(path)) GTEST_SKIP() << "no " << path;
    const std::string program = test::readText(path);
    const MachineModel m = xyzacMachine();
    test::ScratchDir dir("midpoint-bound-impeller");
    test::writeText(dir.file("d.csv"), test::xyzac::kDeviationCsv);
    const DeviationSet d = readDeviationCsv(dir.file("d.csv"), m);
    std::mt19937 rng(3);
    for (const int threads : {1, 2}) {
        const CorrectSummary s = sameWithAndWithout(program, m, d, 30.0, threads);
        std::printf("[midpoint bound] impeller, %d thread(s): %llu of %llu moves' checks settled by the bound, %llu "
                    "split, largest deviation %.4f um\n",
                    threads, static_cast<unsigned long long>(s.boundedChecks), static_cast<unsigned long long>(s.moves),
                    static_cast<unsigned long long>(s.split), s.maxPathDeviation / kUm);
        EXPECT_GT(s.boundedChecks, s.moves * 8 / 10);
    }
    // Twenty times the deviations: more splits, still the same bytes.
    const DeviationSet large = randomLocationErrors(m, rng, 0.2, 200 * kArcsec);
    const CorrectSummary big = sameWithAndWithout(program, m, large, 30.0, 1);
    EXPECT_GT(big.split, 0u);
}

TEST(MidpointBound, ChangesNoByteOfARandomProgramWithLongRotaryMoves) {
    // Straight TCP moves with rotary steps from 0.001 to 15 deg, a tool length change, a pass-through (G53) and an
    // F-only block between them: the bound applies where its premises hold, the exact check elsewhere.
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::string program = "G21 G90 G54 G17\nG43 H1\nM428\nG1 X10 Y0 Z5 A0 C0 F500\n";
    double x = 10, y = 0, z = 5, a = 0, c = 0;
    for (int k = 0; k < 3000; ++k) {
        const double rot = std::array<double, 4>{0.001, 0.2, 2.0, 15.0}[k % 4];
        x = std::clamp(x + 2 * u(rng), -60.0, 60.0), y = std::clamp(y + 2 * u(rng), -60.0, 60.0),
        z = std::clamp(z + u(rng), -20.0, 40.0);
        a = std::clamp(a + rot * u(rng), -80.0, 20.0), c = c + rot * u(rng);
        program += fmt::format("G1 X{:.4f} Y{:.4f} Z{:.4f} A{:.4f} C{:.4f}\n", x, y, z, a, c);
        if (k % 500 == 250) program += "F400\n";
        if (k % 700 == 350) program += "M429\nG53 G0 Z100\nM428\n";
        if (k % 900 == 450) program += "G43 H2\n";
    }
    program += "M429\nM2\n";
    const MachineModel m = xyzacMachine();
    for (const double scale : {1.0, 30.0}) {
        const DeviationSet d = randomLocationErrors(m, rng, 0.01 * scale, 10 * kArcsec * scale);
        CorrectSummary s;
        for (const int threads : {1, 2}) s = sameWithAndWithout(program, m, d, 50.0, threads);
        std::printf("[midpoint bound] random program (deviations x%g): %llu of %llu checks settled, %llu split\n",
                    scale,
                    static_cast<unsigned long long>(s.boundedChecks), static_cast<unsigned long long>(s.moves),
                    static_cast<unsigned long long>(s.split));
        EXPECT_GT(s.boundedChecks, 0u);
    }
}

}  // namespace
}  // namespace cnccomp::postproc
