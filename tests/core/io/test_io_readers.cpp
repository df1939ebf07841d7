// Readers reject malformed input with file:line messages; writers round-trip.
#include <gtest/gtest.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/eccentricity_csv.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "cnccomp/io/trace_csv.hpp"
#include "test_support.hpp"

namespace cnccomp {
using namespace cnccomp::io;
using namespace cnccomp::measurement;
namespace {

// Runs `f`, expects an InputError whose message contains every piece of `parts`.
template <typename F>
void expectInputError(F&& f, std::initializer_list<std::string> parts) {
    try {
        f();
        ADD_FAILURE() << "expected an InputError";
    } catch (const InputError& e) {
        for (const auto& p : parts) EXPECT_NE(std::string(e.what()).find(p), std::string::npos) << e.what() << " lacks " << p;
    }
}

TEST(MachineXml, SampleMachinesLoad) {
    for (const char* name : {"multitasking", "tilting-head-b", "table-table-ac"}) {
        const MachineModel m = readMachineXml(test::sourcePath(std::string("samples/machines/") + name + ".xml"));
        EXPECT_EQ(m.name, name);
        EXPECT_GE(m.axisCount(), 4);
        EXPECT_FALSE(m.deviations.empty());
    }
    const MachineModel& m = test::multitasking();
    EXPECT_EQ(m.axisCount(), 5);
    EXPECT_EQ(m.deviations.size(), 13u);
    EXPECT_EQ(m.deviationIndex("dzBT"), m.deviationIndex("EZ0C1"));
}

TEST(MachineXml, MalformedAndInconsistentFilesNameFileAndLine) {
    test::ScratchDir dir("machine-xml");
    const std::string p = dir.file("m.xml");
    test::writeText(p, "<machine name=\"x\">\n  <tool>\n    <axis name=\"X\" type=\"linear\" direction=\"1 0 0\">\n</machine>\n");
    expectInputError([&] { readMachineXml(p); }, {p, "malformed XML"});
    test::writeText(p, "<machine name=\"x\">\n<tool>\n<axis name=\"X\" type=\"sliding\" direction=\"1 0 0\"/>\n</tool>\n</machine>\n");
    expectInputError([&] { readMachineXml(p); }, {p + ":3", "sliding"});
    test::writeText(p, "<machine name=\"x\">\n<tool>\n<axis name=\"X\" type=\"linear\" direction=\"1 0 nan\"/>\n</tool>\n</machine>\n");
    expectInputError([&] { readMachineXml(p); }, {p + ":3", "direction"});
    test::writeText(p, "<machine name=\"x\">\n<tool>\n<axis name=\"X\" type=\"linear\" direction=\"1 0 0\"/>\n</tool>\n"
                       "<deviations>\n<location name=\"EX0Q\" link=\"Q\" component=\"x\"/>\n</deviations>\n</machine>\n");
    expectInputError([&] { readMachineXml(p); }, {p + ":6", "no link named 'Q'"});
    test::writeText(p, "<machine name=\"x\">\n<tool>\n<axis name=\"X\" type=\"linear\" direction=\"0 0 0\"/>\n</tool>\n</machine>\n");
    expectInputError([&] { readMachineXml(p); }, {p + ":3", "zero"});
    test::writeText(p, "<machine name=\"x\">\n<tool>\n<axis name=\"X\" type=\"linear\" direction=\"1 0 0\" min=\"5\" max=\"-5\"/>\n</tool>\n</machine>\n");
    expectInputError([&] { readMachineXml(p); }, {p + ":3", "min"});
    test::writeText(p, "<plan/>");
    expectInputError([&] { readMachineXml(p); }, {p, "<machine>"});
    expectInputError([&] { readMachineXml(dir.file("missing.xml")); }, {"missing.xml", "cannot open"});
}

TEST(MachineXml, MachineZeroConvertsBetweenCommandsAndControllerCoordinates) {
    test::ScratchDir dir("machine-zero");
    const std::string p = dir.file("m.xml");
    test::writeText(p, "<machine name=\"x\">\n<workpiece>\n<axis name=\"C\" type=\"rotary\" direction=\"0 0 1\" machine-zero=\"90\"/>\n"
                       "</workpiece>\n<tool>\n<axis name=\"X\" type=\"linear\" direction=\"1 0 0\" machine-zero=\"-250\"/>\n"
                       "</tool>\n</machine>\n");
    const MachineModel m = readMachineXml(p);
    EXPECT_TRUE(m.hasMachineZero());
    AxisVector q(2);
    q[m.requireAxis("C")] = 0.0;
    q[m.requireAxis("X")] = 10.0;
    const AxisVector c = m.toController(q);
    EXPECT_NEAR(c[m.requireAxis("C")], -90.0 * kDeg, 1e-15);  // command 0 reads -90 deg on the controller
    EXPECT_NEAR(c[m.requireAxis("X")], 260.0, 1e-12);         // command 10 mm is 260 mm from the controller's zero
    EXPECT_LT((m.fromController(c) - q).norm(), 1e-12);
    EXPECT_FALSE(test::multitasking().hasMachineZero());
    test::writeText(p, "<machine name=\"x\">\n<tool>\n<axis name=\"X\" type=\"linear\" direction=\"1 0 0\" machine-zero=\"abc\"/>\n"
                       "</tool>\n</machine>\n");
    expectInputError([&] { readMachineXml(p); }, {p + ":3", "machine-zero"});
}

TEST(DeviationCsv, RoundTripInMicronsAndArcsecWithAliases) {
    const MachineModel& m = test::multitasking();
    const DeviationSet truth = readDeviationCsv(test::sourcePath("samples/deviations/multitasking-truth.csv"), m);
    EXPECT_NEAR(truth.get("dzBT"), -8.0 * kUm, 1e-15);
    EXPECT_NEAR(truth.get("EA0C1"), 6.5 * kArcsec, 1e-18);
    test::ScratchDir dir("dev-csv");
    writeDeviationCsv(dir.file("d.csv"), truth);
    const std::string text = test::readText(dir.file("d.csv"));
    EXPECT_NE(text.find("EZ0C1,dzBT,-8.000000,um"), std::string::npos) << text;
    EXPECT_NE(text.find("EA0C1,aBT,6.500000,arcsec"), std::string::npos) << text;
    const DeviationSet back = readDeviationCsv(dir.file("d.csv"), m);
    EXPECT_LT((back.values - truth.values).norm(), 1e-12);
}

TEST(DeviationCsv, AcceptsEveryUnitAndEitherColumn) {
    const MachineModel& m = test::multitasking();
    test::ScratchDir dir("dev-units");
    test::writeText(dir.file("d.csv"),
                    "# cnccomp-deviations/2\nname,alias,value,unit\n,dxBT,0.001,mm\nEZ0C1,,2,um\naBT,,1,deg\n,aXB,10,urad\nbXB,,10,um/m\n"
                    "gXB,,0.0001,rad\nEC0Y,,-3,arcsec\n");
    const DeviationSet d = readDeviationCsv(dir.file("d.csv"), m);
    EXPECT_NEAR(d.get("EX0C1"), 1e-3, 1e-15);
    EXPECT_NEAR(d.get("dzBT"), 2e-3, 1e-15);
    EXPECT_NEAR(d.get("aBT"), kDeg, 1e-15);
    EXPECT_NEAR(d.get("aXB"), 1e-5, 1e-18);
    EXPECT_NEAR(d.get("bXB"), 1e-5, 1e-18);
    EXPECT_NEAR(d.get("gXB"), 1e-4, 1e-18);
    EXPECT_NEAR(d.get("EC0Y"), -3 * kArcsec, 1e-18);
    EXPECT_NEAR(d.get("gXY"), 3 * kArcsec, 1e-18);  // ISO EC0Y = -gXY on this machine
    // A header-only file is the all-zero set.
    test::writeText(dir.file("zero.csv"), "name,alias,value,unit\n");
    EXPECT_EQ(readDeviationCsv(dir.file("zero.csv"), m).values.norm(), 0.0);
}

TEST(DeviationCsv, BadRowsNameFileAndLine) {
    const MachineModel& m = test::multitasking();
    test::ScratchDir dir("dev-bad");
    const std::string p = dir.file("d.csv");
    const auto check = [&](const std::string& body, std::initializer_list<std::string> parts) {
        test::writeText(p, "name,alias,value,unit\n" + body);
        expectInputError([&] { readDeviationCsv(p, m); }, parts);
    };
    check("EX0C,dxCZ,1,um\nEQ0Q,,1,um\n", {p + ":3", "unknown deviation 'EQ0Q'"});
    check("EX0C,,nan,um\n", {p + ":2", "finite number"});
    check("EX0C,,1e999,um\n", {p + ":2", "finite number"});
    check("EX0C,,1,furlong\n", {p + ":2", "unknown unit"});
    check("EX0C,,1,arcsec\n", {p + ":2", "a length"});
    check("EX0C,dyCZ,1,um\n", {p + ":2", "different deviations"});
    check("EX0C,,,um\n", {p + ":2", "empty"});
    check("EX0C,,1,um,extra\n", {p + ":2", "cells"});
    test::writeText(p, "");
    expectInputError([&] { readDeviationCsv(p, m); }, {p, "empty file"});
    test::writeText(p, std::string("name,alias\0,value", 17) + "\n");
    expectInputError([&] { readDeviationCsv(p, m); }, {p + ":1", "binary"});
}

TEST(PlanXml, SamplePlanAndErrors) {
    const MeasurementPlan p = readPlanXml(test::sourcePath("samples/plans/multitasking-six-circles.xml"));
    ASSERT_EQ(p.runs.size(), 6u);
    EXPECT_EQ(p.runs[0].test, BallbarTest::BX);
    EXPECT_EQ(p.runs[0].anglesDeg().size(), 360u);  // a full turn does not repeat its first angle
    test::ScratchDir dir("plan");
    writePlanXml(dir.file("p.xml"), p);
    const MeasurementPlan back = readPlanXml(dir.file("p.xml"));
    ASSERT_EQ(back.runs.size(), 6u);
    EXPECT_EQ(back.runs[5].RB, 410);
    EXPECT_EQ(back.runs[4].ZC, 340);
    const std::string f = dir.file("bad.xml");
    test::writeText(f, "<plan>\n<run name=\"a\" test=\"B-Q\" LB=\"100\" RB=\"200\" ZC=\"100\"/>\n</plan>\n");
    expectInputError([&] { readPlanXml(f); }, {f + ":2", "unknown test 'B-Q'"});
    test::writeText(f, "<plan>\n<run name=\"a\" test=\"B-X\" LB=\"-100\" RB=\"200\" ZC=\"100\"/>\n</plan>\n");
    expectInputError([&] { readPlanXml(f); }, {f + ":2", "LB must be positive"});
    test::writeText(f, "<plan>\n<run name=\"a\" test=\"B-X\" LB=\"100\" RB=\"200\" ZC=\"100\" step=\"0\"/>\n</plan>\n");
    expectInputError([&] { readPlanXml(f); }, {f + ":2", "step"});
    test::writeText(f, "<plan>\n<run name=\"a\" test=\"B-X\" LB=\"100\" RB=\"200\"/>\n</plan>\n");
    expectInputError([&] { readPlanXml(f); }, {f + ":2", "'ZC'"});
    test::writeText(f, "<plan>\n</plan>\n");
    expectInputError([&] { readPlanXml(f); }, {f, "at least one"});
}

TEST(TraceAndEccentricityCsv, RoundTripAndErrors) {
    test::ScratchDir dir("trace");
    BallbarTrace t{{0, 1, 2, 3}, {0.001, -0.002, 0.0005, 0}};
    writeTraceCsv(dir.file("t.csv"), t);
    const BallbarTrace back = readTraceCsv(dir.file("t.csv"));
    ASSERT_EQ(back.dL.size(), 4u);
    EXPECT_NEAR(back.dL[1], -0.002, 1e-12);
    test::writeText(dir.file("bad.csv"), "angle_deg,dL_um\n0,1\n1,x\n2,3\n");
    expectInputError([&] { readTraceCsv(dir.file("bad.csv")); }, {"bad.csv:3", "dL_um"});
    test::writeText(dir.file("e.csv"), "test,LB_mm,RB_mm,RC_mm,ZC_mm,ex_um,ey_um,ez_um\nB-X,100,360,50,300,1.5,,2\nQ-X,1,1,1,1,,,\n");
    expectInputError([&] { readEccentricityCsv(dir.file("e.csv")); }, {"e.csv:3", "unknown test 'Q-X'"});
    test::writeText(dir.file("e.csv"), "test,LB_mm,RB_mm,RC_mm,ZC_mm,ex_um,ey_um,ez_um\nB-X,100,360,50,300,1.5,,2\n");
    const auto rows = readEccentricityCsv(dir.file("e.csv"));
    ASSERT_EQ(rows.size(), 1u);
    EXPECT_NEAR(rows[0].e.x(), 1.5e-3, 1e-15);
    EXPECT_TRUE(std::isnan(rows[0].e.y()));
}

}  // namespace
}  // namespace cnccomp
