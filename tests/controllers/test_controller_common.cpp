// The evaluation harness shared by the backends (controllers/common/evaluate) and the header helper.
#include <gtest/gtest.h>

#include <cmath>

#include "cnccomp/error.hpp"
#include "cnccomp/inverse_kinematics.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "controllers/common/evaluate.hpp"
#include "controllers/common/header.hpp"
#include "test_support.hpp"

namespace cnccomp::controllers {
using namespace cnccomp::controllers::common;
using namespace cnccomp::io;
namespace {

/// An ideal controller: solves the exact erroneous model for the nominal pose (what perfect compensation does).
class PerfectCompensation final : public AppliedCompensation {
public:
    PerfectCompensation(const MachineModel& m, const DeviationSet& d, double toolLength)
        : nominal_(m), actual_(m, d), tip_(nominal_.toolPoint(toolLength)) {}
    AxisVector driveCommands(const AxisVector& q) const override {
        return solveToolPose(actual_, toolPose(nominal_, q, tip_), tip_, q).q;
    }

private:
    Kinematics nominal_, actual_;
    Vec3 tip_;
};

TEST(ControllerCommon, WorkspaceSamplesCoverClampedTravel) {
    const MachineModel& m = test::multitasking();  // C B axes rotary, X Y Z linear
    const auto s = workspaceSamples(m, 3, 100.0);
    ASSERT_EQ(s.size(), 243u);  // 3^5
    for (int i = 0; i < m.axisCount(); ++i) {
        double lo = 1e9, hi = -1e9;
        for (const auto& q : s) lo = std::min(lo, q[i]), hi = std::max(hi, q[i]);
        const bool rotary = m.axisLink(i).kind == AxisKind::Rotary;
        EXPECT_NEAR(lo, rotary ? -kPi : -100.0, 1e-12) << m.axisNames[i];
        EXPECT_NEAR(hi, rotary ? kPi : 100.0, 1e-12) << m.axisNames[i];
    }
    const auto one = workspaceSamples(m, 1);
    ASSERT_EQ(one.size(), 1u);
    EXPECT_NEAR(one[0].norm(), 0.0, 1e-12);
    EXPECT_THROW(workspaceSamples(m, 0), ModelError);
}

TEST(ControllerCommon, EvaluateAgainstKnownEffects) {
    const MachineModel& m = test::multitasking();
    DeviationSet d(m);
    d.set("EX0C", 0.015);  // C axis offset in X: tip error is exactly 15 um everywhere (rotated with C)
    const NoCompensation none;
    const auto samples = workspaceSamples(m, 3);
    const CompensationFigures f = evaluateCompensation(m, d, none, samples, 100.0);
    EXPECT_EQ(f.points, 243);
    EXPECT_NEAR(f.maxBefore, 0.015, 1e-12);
    EXPECT_NEAR(f.rmsBefore, 0.015, 1e-12);
    EXPECT_DOUBLE_EQ(f.maxAfter, f.maxBefore);
    EXPECT_NEAR(f.maxAxisBefore, 0.0, 1e-15);

    DeviationSet tilt(m);
    tilt.set("EB0B", 20 * kArcsec);  // zero error of B: axis error is exactly 20"
    const CompensationFigures g = evaluateCompensation(m, tilt, none, samples, 100.0);
    EXPECT_NEAR(g.maxAxisBefore, 20 * kArcsec, 1e-12);
}

TEST(ControllerCommon, PerfectCompensationRemovesTheError) {
    const MachineModel& m = test::multitasking();
    const DeviationSet d = readDeviationCsv(test::sourcePath("samples/deviations/multitasking-truth.csv"), m);
    const PerfectCompensation perfect(m, d, 150.0);
    // Away from the singular orientations (tool axis parallel to C at B = 0, ±180°) where an IK has no unique answer.
    std::vector<AxisVector> samples;
    const int b = m.requireAxis("B");
    for (const AxisVector& q : workspaceSamples(m, 4))
        if (std::abs(std::sin(q[b])) > 0.1) samples.push_back(q);
    ASSERT_EQ(samples.size(), 512u);
    const CompensationFigures f = evaluateCompensation(m, d, perfect, samples, 150.0);
    EXPECT_GT(f.maxBefore, 0.005);
    EXPECT_LT(f.maxAfter, 1e-8);
    EXPECT_LT(f.rmsAfter, f.maxAfter + 1e-15);
    EXPECT_LE(f.maxAxisAfter, f.maxAxisBefore);  // the solver may trade tiny tilts for small rotary moves
}

TEST(ControllerCommon, HeaderListsBothCoverageListsInTheCallersSyntax) {
    const MachineModel& m = test::multitasking();
    DeviationSet d(m);
    EmitResult r;
    r.compensated.push_back({"EX0C", "x-rot-point"});
    r.notCompensated.push_back({"EC0Y", "squareness (not a joint table)"});
    const EmitRequest req{m, d, "truth.csv", "2024-05-01"};
    const HeaderInfo h = makeHeaderInfo(req, "Test controller", r, {"[G] not confirmed"});
    const std::string fanuc = formatHeader(h, "(", ")");
    EXPECT_EQ(fanuc,
              "(cnccomp compensation for Test controller)\n"
              "(machine: multitasking [multitasking.xml])\n"
              "(deviation set: truth.csv)\n"
              "(date: 2024-05-01)\n"
              "(compensated:)\n"
              "(  EX0C  x-rot-point)\n"
              "(NOT compensated:)\n"
              "(  EC0Y  squareness [not a joint table])\n"
              "([G] not confirmed)\n");
    const std::string semi = formatHeader(h, "; ", "", "\r\n");
    EXPECT_NE(semi.find("; machine: multitasking (multitasking.xml)\r\n"), std::string::npos);
    EXPECT_NE(semi.find(";   EC0Y  squareness (not a joint table)\r\n"), std::string::npos);
    EmitResult empty;
    EXPECT_EQ(formatCoverage(empty), "compensated:\n  (none)\nNOT compensated:\n  (none)\n");
}


TEST(ControllerCommon, EmitHelpListsWhatToCheckOnTheControl) {
    const auto help = test::runCli("emit --help");
    ASSERT_EQ(help.exitCode, 0) << help.out;
    EXPECT_NE(help.out.find("Check on the control before loading"), std::string::npos) << help.out;
    int withChecks = 0;
    for (const Backend* b : backends()) {
        const auto list = b->checks();
        if (list.empty()) continue;
        ++withChecks;
        EXPECT_NE(help.out.find(std::string(b->name()) + ":"), std::string::npos) << b->name();
        for (const std::string& item : list) EXPECT_NE(help.out.find(item.substr(0, 40)), std::string::npos) << item;
    }
    EXPECT_GE(withChecks, 4);  // fanuc-30i, heidenhain-tnc, isg, siemens-840d (and generic)
}

TEST(ControllerCommon, FrameNoteNamesTheMachineZeros) {
    MachineModel m = test::multitasking();
    EXPECT_NE(frameNote(m).find("no machine-zero"), std::string::npos);
    for (Chain* c : {&m.workpiece, &m.tool})
        for (Link& l : c->links) {
            if (l.name == "X") l.machineZero = -250.0;
            if (l.name == "C") l.machineZero = 90.0 * kDeg;
        }
    EXPECT_NE(frameNote(m).find("machine-zero (X -250 mm, C 90 deg)"), std::string::npos) << frameNote(m);
}

}  // namespace
}  // namespace cnccomp::controllers
