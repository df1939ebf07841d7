// Plans with the new run kinds (<absolute-run>, <rtest>, <dbb5>) and R-test trace files: round trips, errors that
// name the file and line, and the command line end to end (simulate-runs → rtest / dbb5 / tilting-head).
#include <gtest/gtest.h>

#include <cmath>

#include "cnccomp/error.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "cnccomp/io/rtest_csv.hpp"
#include "test_support.hpp"

namespace cnccomp {
using namespace cnccomp::identification;
using namespace cnccomp::io;
using namespace cnccomp::measurement;
namespace {

const MachineModel& tableTable() {
    static const MachineModel m = readMachineXml(test::sourcePath("samples/machines/table-table-ac.xml"));
    return m;
}

template <typename F>
void expectInputError(F&& f, std::initializer_list<std::string> parts) {
    try {
        f();
        ADD_FAILURE() << "expected an InputError";
    } catch (const InputError& e) {
        for (const auto& p : parts) EXPECT_NE(std::string(e.what()).find(p), std::string::npos) << e.what() << " lacks " << p;
    }
}

TEST(RtestIo, SamplePlansLoadAndRoundTrip) {
    for (const char* name : {"table-table-ac-rtest", "table-table-ac-kinematic", "dbb5-table-table-ac", "tilting-head-b-patterns",
                             "multitasking-six-circles"}) {
        const MeasurementPlan p = readPlanXml(test::sourcePath(std::string("samples/plans/") + name + ".xml"));
        test::ScratchDir dir("plan-rt");
        writePlanXml(dir.file("p.xml"), p);
        const MeasurementPlan q = readPlanXml(dir.file("p.xml"));
        EXPECT_EQ(formatPlanXml(p), formatPlanXml(q)) << name;
        EXPECT_EQ(q.runCount(), p.runCount()) << name;
    }
    const MeasurementPlan r = readPlanXml(test::sourcePath("samples/plans/table-table-ac-rtest.xml"));
    ASSERT_EQ(r.rtestRuns.size(), 5u);
    EXPECT_EQ(r.rtestRuns[2].sweeps[0].axis, "A");
    EXPECT_EQ(r.rtestRuns[2].sweeps[0].startDeg, 45);
    EXPECT_EQ(r.rtestRuns[2].sweeps[0].endDeg, 45);
    const MeasurementPlan d = readPlanXml(test::sourcePath("samples/plans/dbb5-table-table-ac.xml"));
    ASSERT_EQ(d.dbb5Runs.size(), 11u);
    EXPECT_EQ(d.dbb5Runs[3].kind, Dbb5Run::Kind::RotaryCircle);
    EXPECT_EQ(d.dbb5Runs[3].barDirection, -Vec3::UnitX());
    EXPECT_EQ(readPlanXml(test::sourcePath("samples/plans/tilting-head-b-patterns.xml")).absoluteRuns.size(), 6u);
}

TEST(RtestIo, WritersMatchGoldenText) {
    MeasurementPlan p;
    p.machine = "table-table-ac";
    p.description = "golden";
    RtestRun r;
    r.name = "XYC";
    r.ball = Vec3(150, 0, 100);
    r.steps = 4;
    r.sweeps = {{"A", 0, 0}, {"C", 0, 360}};
    p.rtestRuns.push_back(r);
    Dbb5Run d;
    d.name = "C-X";
    d.kind = Dbb5Run::Kind::RotaryCircle;
    d.axis = "C";
    d.barDirection = -Vec3::UnitX();
    d.ball = Vec3(100, 0, 50);
    d.hold = {{"A", 0}};
    p.dbb5Runs.push_back(d);
    EXPECT_EQ(formatPlanXml(p),
              "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
              "<plan machine=\"table-table-ac\" description=\"golden\">\n"
              "  <rtest name=\"XYC\" ball=\"150 0 100\" nest-length=\"100\" steps=\"4\">\n"
              "    <hold axis=\"A\" deg=\"0\"/>\n"
              "    <sweep axis=\"C\" start=\"0\" end=\"360\"/>\n"
              "  </rtest>\n"
              "  <dbb5 name=\"C-X\" kind=\"rotary\" LB=\"100\" tool-length=\"100\" ball=\"100 0 50\" start=\"0\" end=\"360\" "
              "step=\"5\" axis=\"C\" direction=\"-1 0 0\" setup=\"0\">\n"
              "    <hold axis=\"A\" deg=\"0\"/>\n"
              "  </dbb5>\n"
              "</plan>\n");
    const MachineModel& m = tableTable();
    RtestTrace t;
    t.commands = rtestCommands(m, r);
    for (size_t i = 0; i < t.commands.size(); ++i) t.d.push_back(Vec3(1e-3 * i, -2e-3, 0.5e-3));
    test::ScratchDir dir("rtest-golden");
    writeRtestCsv(dir.file("g.csv"), m, t);
    EXPECT_EQ(test::readText(dir.file("g.csv")),
              "pose,A_deg,C_deg,Y_mm,X_mm,Z_mm,dx_um,dy_um,dz_um\n"
              "1,0.000000000,0.000000000,0.000000000,150.000000000,200.000000000,0.000000,-2.000000,0.500000\n"
              "2,0.000000000,90.000000000,150.000000000,0.000000000,200.000000000,1.000000,-2.000000,0.500000\n"
              "3,0.000000000,180.000000000,0.000000000,-150.000000000,200.000000000,2.000000,-2.000000,0.500000\n"
              "4,0.000000000,270.000000000,-150.000000000,0.000000000,200.000000000,3.000000,-2.000000,0.500000\n");
}

TEST(RtestIo, PlanErrorsNameFileAndLine) {
    test::ScratchDir dir("plan-err");
    const std::string f = dir.file("p.xml");
    test::writeText(f, "<plan>\n<rtest name=\"a\" ball=\"1 2 3\">\n<sweep axis=\"C\" start=\"0\"/>\n</rtest>\n</plan>\n");
    expectInputError([&] { readPlanXml(f); }, {f + ":3", "'end'"});
    test::writeText(f, "<plan>\n<rtest name=\"a\" ball=\"1 2 3\">\n<hold axis=\"C\" deg=\"10\"/>\n</rtest>\n</plan>\n");
    expectInputError([&] { readPlanXml(f); }, {f + ":2", "no rotary axis moves"});
    test::writeText(f, "<plan>\n<rtest name=\"a\" ball=\"1 2 3\" steps=\"2.5\"><sweep axis=\"C\" start=\"0\" end=\"9\"/></rtest>\n</plan>\n");
    expectInputError([&] { readPlanXml(f); }, {f + ":2", "whole number"});
    test::writeText(f, "<plan>\n<dbb5 name=\"a\" kind=\"linear\" plane=\"XQ\" LB=\"100\" ball=\"0 0 0\"/>\n</plan>\n");
    expectInputError([&] { readPlanXml(f); }, {f + ":2", "plane 'XQ'"});
    test::writeText(f, "<plan>\n<dbb5 name=\"a\" kind=\"rotary\" axis=\"C\" LB=\"100\" ball=\"0 0 0\"/>\n</plan>\n");
    expectInputError([&] { readPlanXml(f); }, {f + ":2", "direction"});
    test::writeText(f, "<plan>\n<dbb5 name=\"a\" kind=\"rotary\" axis=\"C\" direction=\"0 0 0\" LB=\"100\" ball=\"0 0 0\"/>\n</plan>\n");
    expectInputError([&] { readPlanXml(f); }, {f + ":2", "non-zero"});
    test::writeText(f, "<plan>\n<absolute-run name=\"a\" test=\"B-X\" LB=\"100\" RB=\"200\" ZC=\"0\" estimate-mounting=\"tool\"/>\n</plan>\n");
    expectInputError([&] { readPlanXml(f); }, {f + ":2", "none or work"});
    test::writeText(f, "<plan>\n<run name=\"a\" test=\"B-X\" LB=\"100\" RB=\"200\" ZC=\"0\"/>\n"
                       "<dbb5 name=\"a\" kind=\"linear\" plane=\"XY\" LB=\"100\" ball=\"0 0 0\"/>\n</plan>\n");
    expectInputError([&] { readPlanXml(f); }, {f + ":3", "used twice"});
    test::writeText(f, "<plan>\n<probe name=\"a\"/>\n</plan>\n");
    expectInputError([&] { readPlanXml(f); }, {f + ":2", "expected <run>, <absolute-run>, <rtest>, <dbb5>, <circle> or <sphere>"});
}

TEST(RtestIo, TraceCsvRoundTripAndMismatchErrors) {
    const MachineModel& m = tableTable();
    const MeasurementPlan p = readPlanXml(test::sourcePath("samples/plans/table-table-ac-rtest.xml"));
    const DeviationSet d = readDeviationCsv(test::sourcePath("samples/deviations/table-table-ac-truth.csv"), m);
    const RtestRun& run = p.rtestRuns[1];
    const RtestTrace t = simulateRtest(Kinematics(m, d), run);
    test::ScratchDir dir("rtest-csv");
    writeRtestCsv(dir.file(run.name + ".csv"), m, t);
    const auto back = readRtestTraces(dir.path.string(), m, {run});
    ASSERT_EQ(back[0].d.size(), t.d.size());
    for (size_t i = 0; i < t.d.size(); ++i) {
        EXPECT_LT((back[0].d[i] - t.d[i]).norm(), 1e-6 * kUm);
        EXPECT_EQ(back[0].commands[i], t.commands[i]);  // the plan's exact commands are kept
    }
    // A file made for another plan: the first differing pose is named with its line.
    std::string text = test::readText(dir.file(run.name + ".csv"));
    const size_t at = text.find("\n3,");
    text.replace(at + 3, 1, "9");
    test::writeText(dir.file(run.name + ".csv"), text);
    expectInputError([&] { readRtestTraces(dir.path.string(), m, {run}); }, {run.name + ".csv:4", "differs from the plan"});
    test::writeText(dir.file(run.name + ".csv"), "pose,Y_mm,X_mm,Z_mm,A_deg,C_deg,dx_um,dy_um\n1,0,0,0,0,0,1,2\n");
    expectInputError([&] { readRtestCsv(dir.file(run.name + ".csv"), m); }, {"dz_um"});
    test::writeText(dir.file(run.name + ".csv"), "pose,Y_mm,X_mm,Z_mm,A_deg,C_deg,dx_um,dy_um,dz_um\n1,0,0,0,0,0,1,nan,3\n");
    expectInputError([&] { readRtestCsv(dir.file(run.name + ".csv"), m); }, {":2"});
    expectInputError([&] { readRtestTraces(dir.file("missing"), m, {run}); }, {"missing"});
}

TEST(RtestIo, CommandLineEndToEnd) {
    test::ScratchDir dir("rtest-cli");
    const std::string m = test::sourcePath("samples/machines/table-table-ac.xml");
    const std::string plan = test::sourcePath("samples/plans/table-table-ac-rtest.xml");
    const std::string truth = test::sourcePath("samples/deviations/table-table-ac-truth.csv");
    auto r = test::runCli("simulate --machine " + m + " --plan " + plan + " --deviations " + truth + " --out " +
                          dir.file("traces"));
    ASSERT_EQ(r.exitCode, 0) << r.out;
    const MachineModel& mm = tableTable();
    const DeviationSet want = readDeviationCsv(truth, mm);
    // The plan's runs (one ball) choose the R-test location method; both the least squares (default) and the
    // paper's fits (refined) recover the eleven errors under their ISO names.
    for (const std::string method : {"least-squares", "formulas"}) {
        r = test::runCli("identify --machine " + m + " --plan " + plan + " --traces " + dir.file("traces") + " --method " +
                         method + " --out " + dir.file(method + ".csv") + " --volumetric XYZAC --volumetric-out " +
                         dir.file(method + "-v.csv"));
        ASSERT_EQ(r.exitCode, 0) << r.out;
        EXPECT_NE(r.out.find("volumetric error along 'XYZAC'"), std::string::npos) << r.out;
        EXPECT_NE(r.out.find("R-test location"), std::string::npos) << r.out;
        EXPECT_TRUE(std::filesystem::exists(dir.file(method + "-v.csv")));
        const DeviationSet got = readDeviationCsv(dir.file(method + ".csv"), mm);
        for (const char* n : {"EY0A", "EZ0A", "EB0A", "EC0A", "EX0C", "EY0C", "EA0C", "EB0C", "EC0Y", "EB0Z", "EA0Z"}) {
            const bool angle = mm.deviations[mm.deviationIndex(n)].isAngle();
            EXPECT_NEAR(got.get(n), want.get(n), angle ? 0.001 * kArcsec : 0.001 * kUm) << method << " " << n;
        }
    }
    // A missing trace file: exit code 2 and the file's name; no output written. (The three-ball plan chooses the
    // R-test tables method.)
    r = test::runCli("identify --machine " + m + " --plan " + test::sourcePath("samples/plans/table-table-ac-kinematic.xml") +
                     " --traces " + dir.file("traces") + " --out " + dir.file("k.csv"));
    EXPECT_EQ(r.exitCode, 2) << r.out;
    EXPECT_NE(r.out.find("C-ball1.csv"), std::string::npos) << r.out;
    EXPECT_FALSE(std::filesystem::exists(dir.file("k.csv")));
    // A one-ball plan does not fit the tables method, and says which method it fits.
    r = test::runCli("identify --machine " + m + " --plan " + plan + " --traces " + dir.file("traces") +
                     " --measure rtest-tables --out " + dir.file("t.csv"));
    EXPECT_EQ(r.exitCode, 2) << r.out;
    EXPECT_NE(r.out.find("fits 'rtest-location'"), std::string::npos) << r.out;
    EXPECT_FALSE(std::filesystem::exists(dir.file("t.csv")));
    // The output must not overwrite an input.
    r = test::runCli("identify --machine " + m + " --plan " + plan + " --traces " + dir.file("traces") + " --out " + plan);
    EXPECT_EQ(r.exitCode, 2) << r.out;
}

}  // namespace
}  // namespace cnccomp
