// The review's defects 5–10 of `cnccomp correct`, each with the case that showed it: moves outside the
// travel are reported; a move after a block passed through is not split for an offset splitting cannot remove;
// --strict gives a non-zero exit status; near the singular pose of an A/C table the rotary solution stays continuous;
// a tolerance below the output resolution is clamped and reported; words appended to a block follow its spacing.
#include <gtest/gtest.h>

#include <cmath>
#include <regex>
#include <sstream>

#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "cnccomp/kinematics.hpp"
#include "postproc/correct_program.hpp"
#include "test_support.hpp"

namespace cnccomp::postproc {
using namespace cnccomp::io;
namespace {

const DeviationSet& multitaskingTruth() {
    static const DeviationSet d =
        readDeviationCsv(test::sourcePath("samples/deviations/multitasking-truth.csv"), test::multitasking());
    return d;
}

CorrectSummary run(const MachineModel& m, const DeviationSet& d, const std::string& program, std::string& out,
                   CorrectOptions o = {}) {
    o.dialect = Dialect::Rs274ngc;
    if (o.setup.defaultToolLength == 0) o.setup.addToolLength("100");
    std::istringstream in(program);
    std::ostringstream os;
    const CorrectSummary s = correctProgram(m, d, in, os, o);
    out = os.str();
    return s;
}

bool warned(const CorrectSummary& s, uint64_t line, const std::string& words) {
    for (const Notice& n : s.warnings)
        if (n.line == line && n.message.find(words) != std::string::npos) return true;
    return false;
}

std::vector<std::string> lines(const std::string& text) {
    std::vector<std::string> v;
    std::istringstream in(text);
    for (std::string l; std::getline(in, l);) v.push_back(l);
    return v;
}

TEST(PostprocReview, MovesOutsideTheTravelAreReported) {
    const MachineModel& m = test::multitasking();
    const int x = m.requireAxis("X");
    const double beyond = m.axisLink(x).max + 5.0;
    const std::string program = "G21 G90 G0 X10 Y0 Z100 B0 C0\nG1 X" + std::to_string(beyond) + " F100\nG1 X20\n";
    std::string out;
    const CorrectSummary s = run(m, multitaskingTruth(), program, out);
    EXPECT_EQ(s.outsideTravel, 1u) << formatSummary(s);
    EXPECT_TRUE(warned(s, 2, "axis X")) << formatSummary(s);
    EXPECT_TRUE(warned(s, 2, "outside its travel"));
    EXPECT_FALSE(warned(s, 3, "outside its travel"));
    EXPECT_NE(formatSummary(s).find("outside the travel"), std::string::npos) << formatSummary(s);
}

TEST(PostprocReview, AMoveAfterAPassedThroughBlockIsNotSplitForItsStartOffset) {
    // Line 3 is passed through (a U word the machine does not have): the machine ends there uncorrected, ~30 um off.
    // Line 4 starts from there in G93: splitting cannot remove that offset, so it must not split to the depth limit.
    const MachineModel& m = test::multitasking();
    const std::string program =
        "G21 G90 G94 G0 X40 Y0 Z100 B0 C0\n"
        "G1 X35 Y2 Z100 B5 C10 F200\n"
        "G1 X30 Y4 Z100 B10 C20 U1\n"
        "G93 G1 X25 Y6 Z100 B15 C30 F20\n"
        "G1 X20 Y8 Z100 B20 C40 F20\n";
    std::string out;
    CorrectOptions o;
    o.corrector.toleranceMm = 0.5 * kUm;
    const CorrectSummary s = run(m, multitaskingTruth(), program, out, o);
    EXPECT_EQ(s.limited, 0u) << formatSummary(s);
    EXPECT_EQ(s.offPathStarts, 1u) << formatSummary(s);
    EXPECT_LE(s.addedLines, 4u) << out;  // before the fix: +14 lines and feeds up to 16384 x in G93
    for (const std::string& l : lines(out)) {
        const size_t f = l.find('F');
        if (f != std::string::npos && l.find("G93") != std::string::npos) {
            EXPECT_LT(std::stod(l.substr(f + 1)), 200.0) << l;
        }
    }
    EXPECT_NE(out.find("G93 G1 X2"), std::string::npos) << out;
}

TEST(PostprocReview, StrictExitStatusWhenAnythingIsLeftUncorrected) {
    test::ScratchDir dir("pp-strict");
    const std::string m = test::sourcePath("samples/machines/multitasking.xml");
    const std::string d = test::sourcePath("samples/deviations/multitasking-truth.csv");
    test::writeText(dir.file("clean.nc"), "G21 G90 G0 X10 Y0 Z100 B0 C0\nG1 X20 F100\n");
    test::writeText(dir.file("macro.nc"), "G21 G90 G0 X10 Y0 Z100 B0 C0\n#1=5\nG1 X#1 F100\nG1 X20\n");
    const std::string base = "correct --machine " + m + " --deviations " + d + " --tool-length 100 --out " + dir.file("o.nc");
    auto r = test::runCli(base + " --in " + dir.file("macro.nc"));
    EXPECT_EQ(r.exitCode, 0) << r.out;
    r = test::runCli(base + " --in " + dir.file("macro.nc") + " --strict");
    EXPECT_EQ(r.exitCode, 3) << r.out;
    EXPECT_NE(r.out.find("--strict: 2 block(s) left uncorrected"), std::string::npos) << r.out;
    EXPECT_TRUE(std::filesystem::exists(dir.file("o.nc")));  // the output is still written
    r = test::runCli(base + " --in " + dir.file("clean.nc") + " --strict");
    EXPECT_EQ(r.exitCode, 0) << r.out;
}

TEST(PostprocReview, RotarySolutionStaysContinuousNearTheSingularPose) {
    // A/C table, truth set x 20, a program at C0 with A wandering around 0 (the tool axis along C): the C correction
    // stays small and changes little from block to block; the tip still follows the nominal path.
    const MachineModel m = readMachineXml(test::sourcePath("samples/machines/table-table-ac.xml"));
    DeviationSet d = readDeviationCsv(test::sourcePath("samples/deviations/table-table-ac-truth.csv"), m);
    d.values *= 20.0;
    std::string program = "G21 G90 G17\nG0 X0 Y0 Z50 A0 C0\nG1 F500\n";
    char buf[128];
    for (int k = 0; k < 200; ++k) {
        std::snprintf(buf, sizeof buf, "G1 X%.4f Y%.4f Z10 A%.4f C0\n", 40 * std::cos(k * 0.05), 40 * std::sin(k * 0.05),
                      0.3 * std::sin(k * 0.3));
        program += buf;
    }
    std::string out;
    const CorrectSummary s = run(m, d, program, out);
    const std::regex cWord("C(-?[0-9.]+)");
    double lo = 0, hi = 0, step = 0, prev = 0;
    bool first = true;
    for (const std::string& l : lines(out)) {
        std::smatch mm;
        if (l.rfind("G1 X", 0) != 0 || !std::regex_search(l, mm, cWord)) continue;
        const double c = std::stod(mm[1]);
        lo = std::min(lo, c), hi = std::max(hi, c);
        if (!first) step = std::max(step, std::fabs(c - prev));
        prev = c, first = false;
    }
    std::printf("[ singular ] C within %.4f .. %.4f deg, largest change between blocks %.4f deg, +%llu lines\n", lo, hi,
                step, static_cast<unsigned long long>(s.addedLines));
    // Before: C between -13.3 and +12.8 deg, 168 moves split (+2679 lines) and tolerance not met.
    EXPECT_LT(std::max(-lo, hi), 0.25);
    EXPECT_LT(step, 0.1);
    EXPECT_EQ(s.limited, 0u) << formatSummary(s);
    EXPECT_LE(s.addedLines, 10u);
    EXPECT_LT(s.maxTipResidual, 2e-6);  // mm: measured before the last step, the solver's tolerance is 1e-6 mm
}

TEST(PostprocReview, ToleranceBelowTheOutputResolutionIsClampedAndSaid) {
    const std::string program = test::readText(test::sourcePath("samples/gcode/multitasking-5axis.ngc"));
    const MachineModel& m = test::multitasking();
    CorrectOptions fine, floor;
    fine.corrector.toleranceMm = 0.02 * kUm;
    std::string out;
    const CorrectSummary s = run(m, multitaskingTruth(), program, out, fine);
    EXPECT_GT(s.clampedTolerance, 0u);
    EXPECT_GT(s.toleranceFloor, 0.02 * kUm);
    ASSERT_FALSE(s.warnings.empty());
    bool said = false;
    for (const Notice& n : s.warnings) said = said || n.message.find("below what the written digits can hold") != std::string::npos;
    EXPECT_TRUE(said) << formatSummary(s);
    EXPECT_NE(formatSummary(s).find("tolerance raised to"), std::string::npos) << formatSummary(s);
    // At the floor itself the program grows the same: the finer request no longer multiplies it.
    floor.corrector.toleranceMm = s.toleranceFloor;
    const CorrectSummary f = run(m, multitaskingTruth(), program, out, floor);
    EXPECT_LE(s.addedLines, f.addedLines + f.addedLines / 10 + 5) << s.addedLines << " vs " << f.addedLines;
    EXPECT_EQ(s.limited, 0u);
}

TEST(PostprocReview, AppendedWordsFollowTheBlocksSpacing) {
    // Squareness only: Y and Z corrections appear on blocks that name X only. Each block's own spacing is kept:
    // aligned columns with a space for the sign, plain single spaces, and no spaces at all.
    const MachineModel& m = test::multitasking();
    DeviationSet d(m);
    d.setLinkValue("EC0Y", 200 * kArcsec);  // the X slide turned about Z (ISO EC0Y = -200")
    d.setLinkValue("EA0Z", 150 * kArcsec);
    std::string out;
    run(m, d,
        "G21 G90 G0 X 0 Y 0 Z 100 B0 C0\n"
        "G1  X  50.000  F 100\n"
        "G1  X -50.000\n"
        "G1 X 60.000\n"
        "G1X70.000\n",
        out);
    const auto l = lines(out);
    ASSERT_EQ(l.size(), 5u) << out;
    EXPECT_TRUE(std::regex_search(l[1], std::regex("^G1  X  50\\.\\d+  Y -0\\.\\d+  F 100$"))) << l[1];
    EXPECT_TRUE(std::regex_search(l[2], std::regex("^G1  X -50\\.\\d+  Y -0\\.\\d+$"))) << l[2];
    EXPECT_TRUE(std::regex_search(l[3], std::regex("^G1 X 60\\.\\d+ Y -0\\.\\d+$"))) << l[3];
    EXPECT_TRUE(std::regex_search(l[4], std::regex("^G1X70\\.\\d+Y-0\\.\\d+$"))) << l[4];
    // A positive number in a sign-aligned column takes the minus sign's place.
    run(m, d, "G21 G90 G0 X -5.000  Y  1.000  Z  100.000  B0 C0\nG1  X -50.000  F 100\n", out);
    EXPECT_TRUE(std::regex_search(lines(out)[1], std::regex("^G1  X -50\\.\\d+  Y  [01]\\.\\d+  F 100$"))) << out;
}

}  // namespace
}  // namespace cnccomp::postproc
