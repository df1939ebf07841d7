// verify of the ISO 230-4 circles of the linear axes (<circle> runs, app/verify.cpp): the test programs re-simulated
// with the compensation, before and after, with the ISO 230-4 figures. Oracles: before = the circle simulation
// (simulateLinearCircle) on the true machine; after the ideal compensation of the identified squareness = the same
// simulation on the true machine without its squareness (what is left is the scale and straightness the circles cannot
// put into the set); a wrong-sign file doubles the squareness and verify flags it as worse (exit 1).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include <fmt/format.h>

#include "app/verify.hpp"
#include "cnccomp/circular_test.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "cnccomp/linear_circle_run.hpp"
#include "test_support.hpp"

namespace cnccomp {
namespace {

std::string src(const std::string& rel) { return test::sourcePath(rel); }

/// G (mm) of each pass of the circle simulated on machine k, cut to the data arc (the simulation adds the overshoot).
std::vector<double> simulatedG(const Kinematics& k, const LinearCircleRun& run) {
    std::vector<double> g;
    for (const DirectedTrace& d : simulateLinearCircle(k, run)) {
        BallbarTrace t;
        for (size_t i = 0; i < d.trace.angleDeg.size(); ++i)
            if (d.trace.angleDeg[i] >= run.startDeg - 1e-9 && d.trace.angleDeg[i] <= run.endDeg() + 1e-9) {
                t.angleDeg.push_back(d.trace.angleDeg[i]);
                t.dL.push_back(d.trace.dL[i]);
            }
        g.push_back(evaluateCircularTest(t, run.radius).circularity);
    }
    return g;
}

TEST(VerifyCircles, TheIdealCompensationOfTheSquarenessLeavesTheCirclesOfTheMachineWithoutIt) {
    const MachineModel m = readMachineXml(src("samples/machines/mill-3axis.xml"));
    const MeasurementPlan plan = readPlanXml(src("samples/plans/mill-3axis-circles.xml"));
    const DeviationSet truth = readDeviationCsv(src("samples/deviations/mill-3axis-truth.csv"), m);
    DeviationSet squareness(m), rest = truth;  // what identify writes from the circles, and what it cannot
    for (const char* n : {"EC0Y", "EA0Z", "EB0Z"}) {
        squareness.set(n, truth.get(n));
        rest.set(n, 0.0);
    }
    VerifyCompensation comp;
    comp.kind = VerifyCompensation::Kind::Deviations;
    comp.model = idealCompensation(m, squareness);
    comp.description = "squareness";
    VerifyOptions o;
    o.volumetricPerAxis = 2;
    const VerifyResult r = verify(m, plan, truth, "truth", comp, o);
    ASSERT_EQ(r.runs.size(), plan.circleRuns.size());
    const Kinematics kTruth(m, truth), kRest(m, rest);
    for (size_t i = 0; i < r.runs.size(); ++i) {
        const VerifyRun& run = r.runs[i];
        const LinearCircleRun& c = plan.circleRuns[i];
        EXPECT_EQ(run.type, fmt::format("{} circle (ISO 230-4)", linearPlaneName(c.plane)));
        EXPECT_EQ(run.LB, c.radius);
        const std::vector<double> gBefore = simulatedG(kTruth, c), gAfter = simulatedG(kRest, c);
        ASSERT_EQ(run.passes.size(), gBefore.size()) << run.name;
        const double wantBefore = *std::max_element(gBefore.begin(), gBefore.end());
        const double wantAfter = *std::max_element(gAfter.begin(), gAfter.end());
        double before = 0, after = 0;
        for (const VerifyPass& p : run.passes) {
            ASSERT_TRUE(p.circular) << run.name;
            before = std::max(before, p.isoBefore.circularity);
            after = std::max(after, p.isoAfter.circularity);
        }
        EXPECT_NEAR(before, wantBefore, 0.005 * kUm) << run.name;
        EXPECT_NEAR(after, wantAfter, 0.005 * kUm) << run.name;
        EXPECT_LT(after, before - 0.3 * kUm) << run.name;  // the squareness is a visible part of every circle
    }
    EXPECT_FALSE(r.worse.any());
    EXPECT_LT(r.volumetric.maxAfter, r.volumetric.maxBefore);
    // The programs of the other dialects (G2/G3 of Fanuc and Sinumerik, Klartext CC / C) read back to the same circles.
    for (const auto d : {pp::Dialect::Fanuc, pp::Dialect::Sinumerik, pp::Dialect::Heidenhain}) {
        VerifyOptions od = o;
        od.dialect = d;
        const VerifyResult rd = verify(m, plan, truth, "truth", comp, od);
        EXPECT_NEAR(rd.residualBefore, r.residualBefore, 1e-6) << static_cast<int>(d);
        EXPECT_NEAR(rd.residual, r.residual, 1e-6) << static_cast<int>(d);
    }
}

// Through the executable: identify's own set improves every circle (exit 0); the same set with the sign turned makes
// every circle worse and verify says so (exit 1, banner), as it does for the rotary-axis runs.
TEST(VerifyCircles, TheCliImprovesWithTheIdentifiedSetAndFlagsAWrongSign) {
    const test::ScratchDir dir("verify-circles");
    const std::string machine = src("samples/machines/mill-3axis.xml"), plan = src("samples/plans/mill-3axis-circles.xml"),
                      truth = src("samples/deviations/mill-3axis-truth.csv");
    ASSERT_EQ(test::runCli(fmt::format("simulate --machine '{}' --plan '{}' --deviations '{}' --out '{}'", machine, plan, truth,
                                       dir.file("traces"))).exitCode, 0);
    ASSERT_EQ(test::runCli(fmt::format("identify --machine '{}' --plan '{}' --traces '{}' --out '{}'", machine, plan,
                                       dir.file("traces"), dir.file("d.csv"))).exitCode, 0);
    const test::CliResult good = test::runCli(fmt::format("verify --machine '{}' --plan '{}' --compensation '{}' --truth '{}'",
                                                          machine, plan, dir.file("d.csv"), truth));
    EXPECT_EQ(good.exitCode, 0) << good.out;
    EXPECT_NE(good.out.find("XY circle (ISO 230-4)"), std::string::npos) << good.out;
    EXPECT_EQ(good.out.find("WORSE"), std::string::npos) << good.out;
    const MachineModel m = readMachineXml(machine);
    DeviationSet wrong = readDeviationCsv(dir.file("d.csv"), m);
    for (const char* n : {"EC0Y", "EA0Z", "EB0Z"}) wrong.set(n, -wrong.get(n));
    test::writeText(dir.file("wrong.csv"), formatDeviationCsv(wrong));
    const test::CliResult bad = test::runCli(fmt::format("verify --machine '{}' --plan '{}' --compensation '{}' --truth '{}'",
                                                         machine, plan, dir.file("wrong.csv"), truth));
    EXPECT_EQ(bad.exitCode, 1) << bad.out;
    EXPECT_NE(bad.out.find("COMPENSATION MAKES THE MACHINE WORSE"), std::string::npos) << bad.out;
}

// The knee mill with table-moving X and Y (the pivot rides on the table): its squareness, identified from its own circles
// and compensated, leaves only the programs' rounding (its truth is squareness alone).
TEST(VerifyCircles, TheKneeMillsCirclesCloseWithItsIdentifiedSquareness) {
    const MachineModel m = readMachineXml(src("samples/machines/mill-3axis-table-xy.xml"));
    const MeasurementPlan plan = readPlanXml(src("samples/plans/mill-3axis-table-xy-circles.xml"));
    const DeviationSet truth = readDeviationCsv(src("samples/deviations/mill-3axis-table-xy-truth.csv"), m);
    VerifyCompensation comp;
    comp.kind = VerifyCompensation::Kind::Deviations;
    comp.model = idealCompensation(m, truth);
    comp.description = "truth";
    VerifyOptions o;
    o.volumetricPerAxis = 2;
    const VerifyResult r = verify(m, plan, truth, "truth", comp, o);
    EXPECT_GT(r.residualBefore, 1.0 * kUm);
    EXPECT_LT(r.residual, 0.01 * kUm);
    for (const VerifyRun& run : r.runs)
        for (const VerifyPass& p : run.passes) EXPECT_LT(p.isoAfter.circularity, 0.01 * kUm) << run.name << " " << p.label;
}

}  // namespace
}  // namespace cnccomp
