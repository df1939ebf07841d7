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
#include "cnccomp/lost_motion.hpp"
#include "controllers/backend.hpp"
#include "test_support.hpp"

namespace cnccomp {
using namespace cnccomp::io;
using namespace cnccomp::measurement;
using namespace app;  // verification (src/app)
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
    app::VerifyCompensation comp;
    comp.kind = app::VerifyCompensation::Kind::Deviations;
    comp.model = app::idealCompensation(m, squareness);
    comp.description = "squareness";
    app::VerifyOptions o;
    o.volumetricPerAxis = 2;
    const app::VerifyResult r = app::verify(m, plan, truth, "truth", comp, o);
    ASSERT_EQ(r.runs.size(), plan.circleRuns.size());
    const Kinematics kTruth(m, truth), kRest(m, rest);
    for (size_t i = 0; i < r.runs.size(); ++i) {
        const app::VerifyRun& run = r.runs[i];
        const LinearCircleRun& c = plan.circleRuns[i];
        EXPECT_EQ(run.type, fmt::format("{} circle (ISO 230-4)", linearPlaneName(c.plane)));
        EXPECT_EQ(run.LB, c.radius);
        const std::vector<double> gBefore = simulatedG(kTruth, c), gAfter = simulatedG(kRest, c);
        ASSERT_EQ(run.passes.size(), gBefore.size()) << run.name;
        const double wantBefore = *std::max_element(gBefore.begin(), gBefore.end());
        const double wantAfter = *std::max_element(gAfter.begin(), gAfter.end());
        double before = 0, after = 0;
        for (const app::VerifyPass& p : run.passes) {
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
    for (const auto d : {postproc::Dialect::Fanuc, postproc::Dialect::Sinumerik, postproc::Dialect::Heidenhain}) {
        app::VerifyOptions od = o;
        od.dialect = d;
        const app::VerifyResult rd = app::verify(m, plan, truth, "truth", comp, od);
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
    app::VerifyCompensation comp;
    comp.kind = app::VerifyCompensation::Kind::Deviations;
    comp.model = app::idealCompensation(m, truth);
    comp.description = "truth";
    app::VerifyOptions o;
    o.volumetricPerAxis = 2;
    const app::VerifyResult r = app::verify(m, plan, truth, "truth", comp, o);
    EXPECT_GT(r.residualBefore, 1.0 * kUm);
    EXPECT_LT(r.residual, 0.01 * kUm);
    for (const app::VerifyRun& run : r.runs)
        for (const app::VerifyPass& p : run.passes) EXPECT_LT(p.isoAfter.circularity, 0.01 * kUm) << run.name << " " << p.label;
}

// Lost motion (the truth's reversal values B<axis>) and LinuxCNC's backlash compensation. Oracle for "before": the
// circle identification's own backlash model (linear_circle_model.hpp, a step b = −B̄ of the axis at each reversal)
// added to the kinematic simulation of the circle on the machine without lost motion: the G of each pass agrees (G is
// taken about the least-squares centre, so the constant the two models differ by does not count). After the LinuxCNC
// files of the same set (route 1: [JOINT_n] BACKLASH = −B̄ in cnccomp-kins.ini; route 2: the reversal in the X/Y/Z.comp
// columns), each pass's G equals the G of the compensation of the set without its reversal on the machine without
// lost motion: the backlash share of the circularity goes to 0.
constexpr double kBx = -4.0, kBy = -2.5, kBz = -3.0;  // um: lost motion 4, 2.5, 3 um

DeviationSet withReversals(DeviationSet d, double sign = 1.0) {
    d.setReversal("X", sign * kBx * kUm);
    d.setReversal("Y", sign * kBy * kUm);
    d.setReversal("Z", sign * kBz * kUm);
    return d;
}

/// The files `emit --controller <emitter>` writes for `d`, applied by the `route` backend's model.
VerifyCompensation controllerFiles(const MachineModel& m, const DeviationSet& d, const char* emitter, const char* route) {
    const controllers::EmitResult e = controllers::backend(emitter).emit({m, d, "set.csv", "2026-11-26"});
    VerifyCompensation comp;
    comp.kind = VerifyCompensation::Kind::ControllerFiles;
    comp.backend = route;
    comp.description = route;
    comp.model = std::shared_ptr<const controllers::AppliedCompensation>(controllers::backend(route).apply(m, e.files));
    return comp;
}

/// The files `emit --controller linuxcnc` writes for `d`, applied by the named LinuxCNC route's model.
VerifyCompensation linuxcncFiles(const MachineModel& m, const DeviationSet& d, const char* route) {
    return controllerFiles(m, d, "linuxcnc", route);
}

double largestG(const VerifyRun& run, bool after) {
    double g = 0;
    for (const VerifyPass& p : run.passes) g = std::max(g, after ? p.isoAfter.circularity : p.isoBefore.circularity);
    return g;
}

TEST(VerifyCircles, LinuxcncBacklashTakesTheTruthsLostMotionOutOfTheCircles) {
    const MachineModel m = readMachineXml(src("samples/machines/mill-3axis.xml"));
    const MeasurementPlan plan = readPlanXml(src("samples/plans/mill-3axis-circles.xml"));
    const DeviationSet geometry = readDeviationCsv(src("samples/deviations/mill-3axis-truth.csv"), m);
    const DeviationSet truth = withReversals(geometry);
    VerifyOptions o;
    o.volumetricPerAxis = 2;
    for (const char* route : {"linuxcnc", "linuxcnc-pins"}) {
        const VerifyResult r = verify(m, plan, truth, "truth", linuxcncFiles(m, truth, route), o);
        const VerifyResult plain = verify(m, plan, geometry, "geometry", linuxcncFiles(m, geometry, route), o);
        ASSERT_EQ(r.runs.size(), plan.circleRuns.size());
        for (size_t i = 0; i < r.runs.size(); ++i) {
            const LinearCircleRun& c = plan.circleRuns[i];
            const VerifyRun& run = r.runs[i];
            // Before: the kinematic trace plus the circle model's backlash signature (b = −B̄ at both ends of u and v).
            const std::array<char, 2> ax = linearPlaneAxes(c.plane);
            const auto b = [](char axis) { return axis == 'X' ? -kBx : axis == 'Y' ? -kBy : -kBz; };
            LinearCircleDiagnostics d;
            d.backlash = {{{b(ax[0]), b(ax[0])}, {b(ax[1]), b(ax[1])}}};
            ASSERT_EQ(run.passes.size(), plain.runs[i].passes.size());
            for (size_t p = 0; p < run.passes.size(); ++p) {
                const VerifyPass& v = run.passes[p];
                const VerifyPass& w = plain.runs[i].passes[p];
                LinearCirclePass pass;
                pass.direction = v.label == "CCW" ? 1 : -1;
                pass.angleDeg = v.before.angleDeg;
                pass.startDeg = v.before.angleDeg.front();
                pass.sweepDeg = std::abs(v.before.angleDeg.back() - v.before.angleDeg.front());
                const std::vector<double> step = predictLinearCircle(c.circle(), pass, d, Eigen::Vector2d::Zero(), 0.0);
                BallbarTrace oracle = w.before;
                for (size_t j = 0; j < oracle.dL.size(); ++j) oracle.dL[j] += step[j];
                const double gOracle = evaluateCircularTest(oracle, c.radius).circularity;
                EXPECT_NEAR(v.isoBefore.circularity, gOracle, 0.01 * kUm) << route << " " << run.name << " " << v.label;
                // The lost motion is a visible part of every circle before, none of it after.
                EXPECT_GT(v.isoBefore.circularity, w.isoBefore.circularity + 1.0 * kUm) << route << " " << run.name << " " << v.label;
                EXPECT_NEAR(v.isoAfter.circularity, w.isoAfter.circularity, 0.01 * kUm) << route << " " << run.name << " " << v.label;
            }
            EXPECT_LT(largestG(run, true), largestG(run, false) - 1.0 * kUm) << route << " " << run.name;
        }
        EXPECT_FALSE(r.worse.any()) << route;
        EXPECT_LT(r.residual, r.residualBefore) << route;
    }
}

// A set whose reversal values have the wrong sign: LinuxCNC's BACKLASH (or the columns) then doubles the lost motion,
// every circle gets worse than without compensation, and verify says so (never "better" when it is worse). The truth
// is lost motion alone, so the files differ from the right ones only by the backlash.
TEST(VerifyCircles, AReversalOfTheWrongSignMakesTheCirclesWorseAndVerifySaysSo) {
    const MachineModel m = readMachineXml(src("samples/machines/mill-3axis.xml"));
    const MeasurementPlan plan = readPlanXml(src("samples/plans/mill-3axis-circles.xml"));
    const DeviationSet truth = withReversals(DeviationSet(m)), wrong = withReversals(DeviationSet(m), -1.0);
    VerifyOptions o;
    o.volumetricPerAxis = 2;
    for (const char* route : {"linuxcnc", "linuxcnc-pins"}) {
        const VerifyResult good = verify(m, plan, truth, "truth", linuxcncFiles(m, truth, route), o);
        const VerifyResult bad = verify(m, plan, truth, "truth", linuxcncFiles(m, wrong, route), o);
        for (size_t i = 0; i < good.runs.size(); ++i) {
            EXPECT_LT(largestG(good.runs[i], true), 0.01 * kUm) << route << " " << good.runs[i].name;
            // Twice the lost motion: the circle's G after is twice its G before.
            EXPECT_NEAR(largestG(bad.runs[i], true), 2 * largestG(bad.runs[i], false), 0.02 * kUm) << route << " " << bad.runs[i].name;
        }
        EXPECT_FALSE(good.worse.any()) << route;
        EXPECT_TRUE(bad.worse.span) << route;
        EXPECT_NEAR(bad.residual, 2 * bad.residualBefore, 0.02 * kUm) << route;
        EXPECT_NE(worseBanner(bad).find("COMPENSATION MAKES THE MACHINE WORSE"), std::string::npos) << route;
    }
    // A backlash on slides without lost motion (the right set's files on the machine without it): the largest span
    // goes down (the geometry's) while the ZX circle gets worse: verify says which run.
    {
        const MachineModel& mm = m;
        const DeviationSet geometry = readDeviationCsv(src("samples/deviations/mill-3axis-truth.csv"), mm);
        const VerifyResult r = verify(mm, plan, geometry, "geometry", linuxcncFiles(mm, withReversals(geometry), "linuxcnc"), o);
        EXPECT_FALSE(r.worse.span);
        ASSERT_FALSE(r.worse.runs.empty());
        EXPECT_EQ(r.worse.runs.front().rfind("zx ", 0), 0u) << r.worse.runs.front();
    }
    // Through the executable: emit the wrong set, verify against the truth: exit 1 and the banner; the right set: exit 0.
    const test::ScratchDir dir("verify-circles-backlash");
    const std::string machine = src("samples/machines/mill-3axis.xml"), planFile = src("samples/plans/mill-3axis-circles.xml");
    test::writeText(dir.file("truth.csv"), formatDeviationCsv(truth));
    test::writeText(dir.file("wrong.csv"), formatDeviationCsv(wrong));
    for (const char* set : {"truth", "wrong"}) {
        ASSERT_EQ(test::runCli(fmt::format("emit --controller linuxcnc --machine '{}' --deviations '{}' --out '{}' --date 2026-11-26",
                                           machine, dir.file(std::string(set) + ".csv"), dir.file(std::string(set) + "-lc"))).exitCode, 0);
        const test::CliResult v = test::runCli(fmt::format("verify --machine '{}' --plan '{}' --compensation '{}' --truth '{}'", machine,
                                                           planFile, dir.file(std::string(set) + "-lc"), dir.file("truth.csv")));
        const bool isWrong = std::string(set) == "wrong";
        EXPECT_EQ(v.exitCode, isWrong ? 1 : 0) << v.out;
        EXPECT_EQ(v.out.find("COMPENSATION MAKES THE MACHINE WORSE") != std::string::npos, isWrong) << v.out;
    }
}

// The other controllers' backlash (Fanuc 1851, Sinumerik MD32450, HEIDENHAIN MP710, ISG getriebe[0].lose; emit writes
// them from the reversal values, controllers/common/set_backlash.hpp): read back by each backend and applied by the
// direction of motion, they take the lost motion out of every circle (what is left: the constant β/2 of the reference
// side, a shift the pivot set-up takes up), and the wrong sign doubles it and is flagged.
TEST(VerifyCircles, EveryControllersBacklashTakesTheLostMotionOutAndAWrongSignIsFlagged) {
    const MachineModel m = readMachineXml(src("samples/machines/mill-3axis.xml"));
    const MeasurementPlan plan = readPlanXml(src("samples/plans/mill-3axis-circles.xml"));
    const DeviationSet truth = withReversals(DeviationSet(m)), wrong = withReversals(DeviationSet(m), -1.0);
    VerifyOptions o;
    o.volumetricPerAxis = 2;
    for (const char* c : {"fanuc-30i", "siemens-840d", "heidenhain-tnc", "isg"}) {
        const VerifyResult good = verify(m, plan, truth, "truth", controllerFiles(m, truth, c, c), o);
        const VerifyResult bad = verify(m, plan, truth, "truth", controllerFiles(m, wrong, c, c), o);
        for (size_t i = 0; i < good.runs.size(); ++i) {
            EXPECT_GT(largestG(good.runs[i], false), 2.0 * kUm) << c << " " << good.runs[i].name;
            EXPECT_LT(largestG(good.runs[i], true), 0.02 * kUm) << c << " " << good.runs[i].name;  // Fanuc: whole detection units
            EXPECT_NEAR(largestG(bad.runs[i], true), 2 * largestG(bad.runs[i], false), 0.05 * kUm) << c << " " << bad.runs[i].name;
        }
        EXPECT_FALSE(good.worse.any()) << c;
        EXPECT_TRUE(bad.worse.span) << c;
    }
}

// The step model of lost_motion.hpp on a hand sequence: directions held at rest, the samples before the first motion
// taking its direction, B̄/2 by direction (oracle: written out by hand).
TEST(LostMotion, DirectionsAndOffsetsByHand) {
    const MachineModel& m = test::sampleMachine("mill-3axis");
    const auto q = [](double x, double y) {
        AxisVector v = AxisVector::Zero(3);
        v << x, y, 0;
        return v;
    };
    const std::vector<AxisVector> path{q(0, 5), q(1, 5), q(2, 4), q(2, 3), q(1, 3), q(1, 3)};
    const std::vector<AxisVector> s = motionDirections(path);
    // X: + up to its reversal at sample 3, − after, held while it rests; Y rests from 0 to 1 before it first moves −:
    // it arrives moving −; Z never moves: 0.
    const double wantX[] = {1, 1, 1, 1, -1, -1}, wantY[] = {-1, -1, -1, -1, -1, -1};
    for (size_t i = 0; i < path.size(); ++i) {
        EXPECT_EQ(s[i][0], wantX[i]) << i;
        EXPECT_EQ(s[i][1], wantY[i]) << i;
        EXPECT_EQ(s[i][2], 0.0) << i;
    }
    DeviationSet d(m);
    d.setReversal("X", -0.004);
    const std::vector<AxisVector> a = withLostMotion(d, path);
    EXPECT_NEAR(a[3][0], 2 - 0.002, 1e-15);  // moving +: lags by |B̄|/2
    EXPECT_NEAR(a[4][0], 1 + 0.002, 1e-15);  // moving −: lags the other way
    EXPECT_EQ(a[4][1], 3.0);                 // Y has no reversal value
}

}  // namespace
}  // namespace cnccomp
