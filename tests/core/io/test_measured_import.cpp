// Measured ball-bar traces: the accepted layouts (angle- and time-sampled, CW and CCW in one file, overshoot, missing
// samples, decimal comma, BOM, own column names and units, drift, relative length) and the checks of a file against
// its run. The files are written here the way an instrument's export would be, from traces simulated on the exact
// model; the oracle is the simulated trace itself (what the import must give back).
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <cmath>
#include <fstream>

#include "cnccomp/error.hpp"
#include "cnccomp/identification/measured_observations.hpp"
#include "cnccomp/io/plan_measurements_io.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "cnccomp/io/trace_csv.hpp"
#include "cnccomp/io/trace_export.hpp"
#include "cnccomp/io/trace_import.hpp"
#include "test_support.hpp"

namespace cnccomp {
using namespace cnccomp::identification;
using namespace cnccomp::io;
using namespace cnccomp::measurement;
namespace {

const MachineModel& machine() { return test::multitasking(); }

DeviationSet truth() {
    static const DeviationSet d = readDeviationCsv(test::sourcePath("samples/deviations/multitasking-truth.csv"), machine());
    return d;
}

BallbarRun cRadial() {
    BallbarRun r;
    r.name = "C-radial";
    r.test = BallbarTest::CRadial;
    r.LB = 100;
    r.RB = 360;
    r.RC = 50;
    r.ZC = 300;
    r.startDeg = 0;
    r.endDeg = 360;
    r.stepDeg = 1;
    return r;
}

/// The trace of `run` over [from, to] deg (to < from: CW) in steps of |step|, simulated on the truth machine.
BallbarTrace simulate(const BallbarRun& run, double from, double to, double step) {
    BallbarRun r = run;
    r.startDeg = from;
    r.endDeg = to;
    r.stepDeg = to >= from ? std::abs(step) : -std::abs(step);
    r.capture = {};
    const Kinematics k(machine(), truth());
    BallbarTrace t = simulateRun(k, r);
    if (std::abs(t.angleDeg.back() - to) > 1e-9) {  // a whole turn: keep the closing sample, as an instrument records it
        BallbarRun last = r;
        last.startDeg = last.endDeg = to;
        last.stepDeg = 1;
        const BallbarTrace e = simulateRun(k, last);
        t.angleDeg.push_back(to);
        t.dL.push_back(e.dL[0]);
    }
    return t;
}

std::string um(double mm) { return fmt::format("{:.6f}", mm / kUm); }

/// Importing must give the simulated samples back (inside the sweep).
void expectSamples(const BallbarTrace& got, const BallbarTrace& want, double tolAngle = 1e-9, double tolDl = 1e-9) {
    ASSERT_EQ(got.dL.size(), want.dL.size());
    for (size_t i = 0; i < got.dL.size(); ++i) {
        EXPECT_NEAR(got.angleDeg[i], want.angleDeg[i], tolAngle) << i;
        EXPECT_NEAR(got.dL[i], want.dL[i], tolDl) << i;
    }
}

void expectInputError(const std::function<void()>& f, std::initializer_list<std::string> parts) {
    try {
        f();
        FAIL() << "no InputError";
    } catch (const InputError& e) {
        for (const std::string& p : parts) EXPECT_NE(std::string(e.what()).find(p), std::string::npos) << e.what() << "\nlacks: " << p;
    }
}

TEST(MeasuredImport, AngleSampledFileWithOvershootAndMissingSamples) {
    test::ScratchDir dir("imp-angle");
    const BallbarRun run = cRadial();
    const BallbarTrace full = simulate(run, -10, 370, 1);  // 10° feed-in and feed-out
    std::string csv = "angle_deg,dL_um\n";
    for (size_t i = 0; i < full.dL.size(); ++i)
        csv += full.angleDeg[i] == 100 ? "100,\n" : fmt::format("{:g},{}\n", full.angleDeg[i], um(full.dL[i]));
    test::writeText(dir.file("t.csv"), csv);
    const MeasuredTrace m = importRunTrace(dir.file("t.csv"), run);
    EXPECT_EQ(m.summary.layout, "angle");
    EXPECT_EQ(m.summary.rows, 381);
    EXPECT_EQ(m.summary.missing, 1);
    EXPECT_EQ(m.summary.trimmed, 20);
    BallbarTrace want = simulate(run, 0, 360, 1);
    want.angleDeg.erase(want.angleDeg.begin() + 100);
    want.dL.erase(want.dL.begin() + 100);
    expectSamples(m.trace, want, 1e-12, 1e-9);
    ASSERT_EQ(m.passes.size(), 1u);
    EXPECT_EQ(m.passes[0].direction, +1);
}

TEST(MeasuredImport, TimeSampledBothDirectionsDecimalCommaBomAndOwnColumns) {
    test::ScratchDir dir("imp-time");
    BallbarRun run = cRadial();
    run.capture.feed = 1000;         // mm/min on the linear axes' circle
    run.capture.overshootDeg = 15;
    run.capture.passes = {+1, -1};
    run.capture.timeColumn = "Time";
    run.capture.lengthColumn = "Deviation";
    run.capture.lengthUnit = 1.0;   // mm
    run.capture.timeUnit = 1e-3;    // ms
    const double radius = linearPathRadius(run);  // |RC − LB| = 50 mm
    ASSERT_NEAR(radius, 50.0, 1e-12);
    const double omega = 1000.0 / 60.0 / radius / kDeg;  // deg/s
    const BallbarTrace ccw = simulate(run, -15, 375, 0.5), cw = simulate(run, 375, -15, 0.5);
    std::string csv = "\xef\xbb\xbf# exported by some ball-bar software\nTime;Deviation\n";
    for (const BallbarTrace* t : {&ccw, &cw}) {
        const double a0 = t == &ccw ? -15.0 : 375.0, d = t == &ccw ? 1.0 : -1.0;
        for (size_t i = 0; i < t->dL.size(); ++i) {
            std::string time = fmt::format("{:.6f}", (t->angleDeg[i] - a0) * d / omega * 1e3), len = fmt::format("{:.9f}", t->dL[i]);
            for (std::string* s : {&time, &len}) std::replace(s->begin(), s->end(), '.', ',');
            csv += time + ";\"" + len + "\"\r\n";
        }
    }
    test::writeText(dir.file("t.csv"), csv);
    const MeasuredTrace m = importRunTrace(dir.file("t.csv"), run);
    EXPECT_EQ(m.summary.layout, "time");
    ASSERT_EQ(m.passes.size(), 2u);
    EXPECT_EQ(m.passes[0].direction, +1);
    EXPECT_EQ(m.passes[1].direction, -1);
    EXPECT_EQ(m.summary.trimmed, 4 * 30);
    expectSamples(m.passes[0].trace, simulate(run, 0, 360, 0.5), 1e-7, 1e-9);
    expectSamples(m.passes[1].trace, simulate(run, 360, 0, 0.5), 1e-7, 1e-9);
    EXPECT_EQ(m.trace.dL.size(), 2 * 721u);
    // The same file without feed in the plan cannot be placed in angle.
    run.capture.feed = 0;
    expectInputError([&] { importRunTrace(dir.file("t.csv"), run); }, {"t.csv:2", "feed"});
}

TEST(MeasuredImport, PassColumnAndReversalSplitBothWork) {
    test::ScratchDir dir("imp-pass");
    BallbarRun run = cRadial();
    run.capture.passes = {-1, +1};  // CW first
    const BallbarTrace cw = simulate(run, 360, 0, 1), ccw = simulate(run, 0, 360, 1);
    std::string withColumn = "angle_deg,dL_um,pass\n", plain = "angle_deg,dL_um\n";
    for (const auto& [t, label] : {std::pair{&cw, "cw"}, {&ccw, "ccw"}})
        for (size_t i = 0; i < t->dL.size(); ++i) {
            withColumn += fmt::format("{:g},{},{}\n", t->angleDeg[i], um(t->dL[i]), label);
            plain += fmt::format("{:g},{}\n", t->angleDeg[i], um(t->dL[i]));
        }
    test::writeText(dir.file("col.csv"), withColumn);
    test::writeText(dir.file("plain.csv"), plain);
    for (const char* f : {"col.csv", "plain.csv"}) {
        const MeasuredTrace m = importRunTrace(dir.file(f), run);
        ASSERT_EQ(m.passes.size(), 2u) << f;
        EXPECT_EQ(m.passes[0].direction, -1);
        expectSamples(m.passes[0].trace, cw, 1e-12, 1e-9);
        expectSamples(m.passes[1].trace, ccw, 1e-12, 1e-9);
    }
    // The plan says CCW first: the file's first pass runs the other way.
    run.capture.passes = {+1, -1};
    expectInputError([&] { importRunTrace(dir.file("col.csv"), run); }, {"col.csv:2", "pass 1 is CW"});
    // One pass planned, two recorded.
    run.capture.passes = {};
    expectInputError([&] { importRunTrace(dir.file("col.csv"), run); }, {"col.csv:", "2 pass(es)", "records 1"});
}

TEST(MeasuredImport, FileIsCheckedAgainstItsRun) {
    test::ScratchDir dir("imp-check");
    BallbarRun run = cRadial();
    const BallbarTrace t = simulate(run, 0, 360, 1);
    // cnccomp's own writer puts the run's metadata in the file.
    writeTraceCsv(dir.file("own.csv"), t, run, "multitasking");
    EXPECT_EQ(importRunTrace(dir.file("own.csv"), run, "multitasking").summary.metadataChecked, 10);
    BallbarRun other = run;
    other.name = "C-radial-ZC2";
    other.ZC = 340;
    expectInputError([&] { importRunTrace(dir.file("own.csv"), other); }, {"own.csv:2", "run 'C-radial'", "another run"});
    expectInputError([&] { importRunTrace(dir.file("own.csv"), run, "table-table-ac"); }, {"own.csv:4", "machine"});
    other = run;
    other.ZC = 340;  // same name, other geometry
    expectInputError([&] { importRunTrace(dir.file("own.csv"), other); }, {"own.csv:", "ZC '300'"});

    // Sweep: a file of a B run (−180..180) given to a 0..360 C run, without metadata.
    std::string csv = "angle_deg,dL_um\n";
    for (int a = -180; a < 180; ++a) csv += fmt::format("{},0.5\n", a);
    test::writeText(dir.file("sweep.csv"), csv);
    expectInputError([&] { importRunTrace(dir.file("sweep.csv"), run); }, {"sweep.csv:", "covers 0..179", "sweeps 0..360"});
    // Direction: decreasing angles in a CCW run.
    csv = "angle_deg,dL_um\n";
    for (int a = 359; a >= 0; --a) csv += fmt::format("{},0.5\n", a);
    test::writeText(dir.file("dir.csv"), csv);
    expectInputError([&] { importRunTrace(dir.file("dir.csv"), run); }, {"dir.csv:3", "goes back", "CCW"});
    // A gap of 20°.
    csv = "angle_deg,dL_um\n";
    for (int a = 0; a < 360; ++a)
        if (a < 100 || a > 119) csv += fmt::format("{},0.5\n", a);
    test::writeText(dir.file("gap.csv"), csv);
    expectInputError([&] { importRunTrace(dir.file("gap.csv"), run); }, {"gap.csv:102", "between 99 and 120"});
    // Recorded with a 5° step where the plan says 1°.
    csv = "angle_deg,dL_um\n";
    for (int a = 0; a <= 360; a += 4) csv += fmt::format("{},0.5\n", a);
    test::writeText(dir.file("coarse.csv"), csv);
    expectInputError([&] { importRunTrace(dir.file("coarse.csv"), run); }, {"coarse.csv:", "91 samples", "gives 361"});
    // Too short to fit.
    BallbarRun arc = run;
    arc.endDeg = 4;
    test::writeText(dir.file("short.csv"), "angle_deg,dL_um\n0,1\n1,1\n2,1\n3,1\n");
    expectInputError([&] { importRunTrace(dir.file("short.csv"), arc); }, {"short.csv:5", "4 sample(s)", "at least 5"});
    // Bad cells name the line and column.
    csv = "angle_deg;dL_um\n";
    for (int a = 0; a <= 360; ++a) csv += a == 7 ? "7;1.000,5\n" : fmt::format("{};1,5\n", a);
    test::writeText(dir.file("bad.csv"), csv);
    expectInputError([&] { importRunTrace(dir.file("bad.csv"), run); }, {"bad.csv:9", "dL_um", "mixed"});
    run.capture.decimal = ',';
    csv = "angle_deg;dL_um\n";
    for (int a = 0; a <= 360; ++a) csv += a == 7 ? "7;1.5\n" : fmt::format("{};1,5\n", a);
    test::writeText(dir.file("bad.csv"), csv);
    expectInputError([&] { importRunTrace(dir.file("bad.csv"), run); }, {"bad.csv:9", "decimal comma"});
    test::writeText(dir.file("utf16.csv"), std::string("\xff\xfe", 2) + "a\0n\0");
    expectInputError([&] { importRunTrace(dir.file("utf16.csv"), run); }, {"utf16.csv:1", "UTF-16"});
    expectInputError([&] { importRunTrace(dir.file("none.csv"), run); }, {"none.csv", "cannot open"});
}

TEST(MeasuredImport, LinearDriftIsRemovedFromAClosedSweep) {
    test::ScratchDir dir("imp-drift");
    BallbarRun run = cRadial();
    const BallbarTrace t = simulate(run, 0, 360, 1);  // 361 samples, the last one at the first's position
    std::string csv = "angle_deg,dL_um\n";
    for (size_t i = 0; i < t.dL.size(); ++i) csv += fmt::format("{:g},{}\n", t.angleDeg[i], um(t.dL[i] + 3 * kUm * i / 360.0));
    test::writeText(dir.file("d.csv"), csv);
    run.capture.removeDrift = true;
    const MeasuredTrace m = importRunTrace(dir.file("d.csv"), run);
    EXPECT_NEAR(m.summary.driftRemoved, 3 * kUm, 1e-9);
    expectSamples(m.trace, t, 1e-12, 1e-9);
    // A half turn in one pass has no two samples at one position.
    run.endDeg = 180;
    test::writeText(dir.file("h.csv"), "angle_deg,dL_um\n" + [&] {
        std::string s;
        for (int a = 0; a <= 180; ++a) s += fmt::format("{},0\n", a);
        return s;
    }());
    expectInputError([&] { importRunTrace(dir.file("h.csv"), run); }, {"h.csv:1", "drift removal needs"});
}

TEST(MeasuredImport, PartialArcInBothDirectionsWithDriftAndHysteresis) {
    test::ScratchDir dir("imp-arc");
    BallbarRun run = cRadial();
    run.name = "B-X";
    run.test = BallbarTest::BX;
    run.startDeg = -110;  // a 220° arc, as ball-bar software records a partial test
    run.endDeg = 110;
    run.capture.passes = {+1, -1};
    run.capture.removeDrift = true;
    const BallbarTrace ccw = simulate(run, -110, 110, 1), cw = simulate(run, 110, -110, 1);
    // The file: CCW then CW, a drift of 0.01 µm per sample, and 2 µm more on the CW pass (backlash-like hysteresis).
    std::string csv = "angle_deg,dL_um\n";
    int row = 0;
    for (const BallbarTrace* t : {&ccw, &cw})
        for (size_t i = 0; i < t->dL.size(); ++i, ++row)
            csv += fmt::format("{:g},{}\n", t->angleDeg[i], um(t->dL[i] + (t == &cw ? 2 * kUm : 0.0) + 0.01 * kUm * row));
    test::writeText(dir.file("arc.csv"), csv);
    const MeasuredTrace m = importRunTrace(dir.file("arc.csv"), run);
    ASSERT_EQ(m.passes.size(), 2u);
    // Drift from both ends: at −110° rows 0 and 441 differ by 2 µm + 4.41 µm, at +110° rows 220 and 221 by 2 µm + 0.01 µm:
    // 4.40 µm over 440 rows. The hysteresis stays.
    EXPECT_NEAR(m.summary.driftRemoved, 0.01 * kUm * 441, 1e-9);
    for (size_t i = 0; i < ccw.dL.size(); ++i) EXPECT_NEAR(m.passes[0].trace.dL[i], ccw.dL[i], 1e-9);
    for (size_t i = 0; i < cw.dL.size(); ++i) EXPECT_NEAR(m.passes[1].trace.dL[i], cw.dL[i] + 2 * kUm, 1e-9);
    EXPECT_NEAR(evaluateCircularRun(m.passes, run.LB).hysteresis, 2 * kUm, 1e-9);
    // Without drift removal the hysteresis is the 2 µm plus the drift between the passes at each angle.
    run.capture.removeDrift = false;
    const MeasuredTrace raw = importRunTrace(dir.file("arc.csv"), run);
    EXPECT_NEAR(evaluateCircularRun(raw.passes, run.LB).hysteresis, 2 * kUm + 0.01 * kUm * 441, 1e-6);  // rows 0 and 441 at −110°
}

TEST(MeasuredImport, InstrumentStyleExportReadsBackAsTheSweep) {
    // Writer and reader are both ours here (a round trip); the oracle is simulateRun over the plan's sweep.
    test::ScratchDir dir("imp-export");
    const Kinematics k(machine(), truth());
    for (const bool time : {false, true})
        for (const char decimal : {'.', ','}) {
            BallbarRun run = cRadial();
            run.capture.feed = 1500;
            run.capture.overshootDeg = 12;
            run.capture.passes = {-1, +1};
            run.capture.decimal = decimal;
            run.capture.lengthColumn = "dL_mm";
            run.capture.lengthUnit = 1.0;
            run.capture.timeUnit = 1e-3;
            const auto passes = simulateCapturedPasses(k, run);
            ASSERT_EQ(passes.size(), 2u);
            EXPECT_EQ(passes[0].trace.dL.size(), 385u);  // 360° + 2 × 12° at 1°, both ends
            test::writeText(dir.file("e.csv"), formatCapturedTrace(run, passes, time, "multitasking"));
            const MeasuredTrace m = importRunTrace(dir.file("e.csv"), run, "multitasking");
            EXPECT_EQ(m.summary.layout, time ? "time" : "angle");
            EXPECT_EQ(m.summary.trimmed, 48);
            EXPECT_EQ(m.summary.metadataChecked, 11);
            ASSERT_EQ(m.passes.size(), 2u);
            expectSamples(m.passes[0].trace, simulate(run, 360, 0, 1), 1e-6, 1e-9);
            expectSamples(m.passes[1].trace, simulate(run, 0, 360, 1), 1e-6, 1e-9);
        }
    // An overshoot the axis cannot travel.
    BallbarRun bx = cRadial();
    bx.test = BallbarTest::BX;
    bx.startDeg = -180;
    bx.endDeg = 180;
    bx.capture.overshootDeg = 10;  // B travels ±185°
    EXPECT_THROW(simulateCapturedPasses(k, bx), ModelError);
}

TEST(MeasuredImport, LinearPathRadiusIsTheRadiusOfTheCommandedCircle) {
    // Independent check of the Table 2 radii: the speed of the commanded (X, Y, Z) along the sweep angle.
    const MachineModel& m = machine();
    const int x = m.requireAxis("X"), y = m.requireAxis("Y"), z = m.requireAxis("Z");
    for (BallbarTest test : kAllBallbarTests) {
        BallbarRun r = cRadial();
        r.test = test;
        r.RC = 70;
        const double h = 1e-6, a = 0.3;
        const AxisVector q1 = runCommands(m, r, a - h), q2 = runCommands(m, r, a + h);
        const Vec3 v((q2[x] - q1[x]) / (2 * h), (q2[y] - q1[y]) / (2 * h), (q2[z] - q1[z]) / (2 * h));
        EXPECT_NEAR(linearPathRadius(r), v.norm(), 1e-6) << testName(test);
    }
}

TEST(MeasuredImport, LengthOffsetObservationJacobianMatchesFiniteDifferences) {
    const MachineModel& m = machine();
    const BallbarRun run = cRadial();
    const BallbarTrace t = simulate(run, 0, 350, 10);
    LengthOffsetObservation o(std::make_unique<BallbarObservation>(m, run, t));
    ASSERT_EQ(o.nuisanceCount(), 1);
    EXPECT_EQ(o.nuisanceNames()[0], "C-radial.dL0");
    const DeviationSet d = truth();
    const DifferentiableMachine dm(m, d);
    std::vector<int> flat;
    for (int i = 0; i < static_cast<int>(m.parameterCount()); ++i) flat.push_back(i);
    const double nu = 7 * kUm;
    Eigen::MatrixXd J(o.size(), static_cast<Eigen::Index>(flat.size()) + 1);
    ASSERT_TRUE(o.jacobian(dm, &nu, flat, J));
    const double h = 1e-7;
    Eigen::VectorXd p(o.size()), q(o.size());
    for (size_t j = 0; j < flat.size(); ++j) {
        DeviationSet a = d, b = d;
        a.values[flat[j]] += h;
        b.values[flat[j]] -= h;
        o.predict(Kinematics(m, a), &nu, p.data());
        o.predict(Kinematics(m, b), &nu, q.data());
        EXPECT_LT(((p - q) / (2 * h) - J.col(static_cast<Eigen::Index>(j))).cwiseAbs().maxCoeff(), 1e-5) << j;
    }
    const double up = nu + h, down = nu - h;
    o.predict(Kinematics(m, d), &up, p.data());
    o.predict(Kinematics(m, d), &down, q.data());
    EXPECT_LT(((p - q) / (2 * h) - J.col(J.cols() - 1)).cwiseAbs().maxCoeff(), 1e-6);
    // The prediction is the inner one plus the offset.
    BallbarObservation inner(m, run, t);
    inner.predict(Kinematics(m, d), nullptr, q.data());
    o.predict(Kinematics(m, d), &nu, p.data());
    EXPECT_NEAR((p - q).maxCoeff(), nu, 1e-12);
    EXPECT_NEAR((p - q).minCoeff(), nu, 1e-12);
}

TEST(MeasuredImport, PlanCaptureAttributesReadBackAndAreChecked) {
    test::ScratchDir dir("imp-plan");
    const std::string f = dir.file("p.xml");
    test::writeText(f, "<plan machine=\"multitasking\">\n"
                       "  <instrument time-column=\"Time\" length-column=\"Deviation\" length-unit=\"mm\" time-unit=\"ms\" "
                       "decimal=\"comma\" length=\"relative\" drift=\"remove\"/>\n"
                       "  <run name=\"a\" test=\"C-radial\" LB=\"100\" RB=\"360\" RC=\"50\" ZC=\"300\" feed=\"1000\" overshoot=\"15\" "
                       "directions=\"cw ccw\"/>\n"
                       "  <run name=\"b\" test=\"B-X\" LB=\"100\" RB=\"360\" ZC=\"300\" start=\"-90\" end=\"90\" length=\"absolute\"/>\n"
                       "</plan>\n");
    const MeasurementPlan p = readPlanXml(f);
    const RunCapture& a = p.runs[0].capture;
    EXPECT_EQ(a.feed, 1000);
    EXPECT_EQ(a.overshootDeg, 15);
    EXPECT_EQ(a.passes, (std::vector<int>{-1, +1}));
    EXPECT_EQ(a.timeColumn, "Time");
    EXPECT_EQ(a.lengthUnit, 1.0);
    EXPECT_EQ(a.timeUnit, 1e-3);
    EXPECT_EQ(a.decimal, ',');
    EXPECT_TRUE(a.relativeLength);
    EXPECT_TRUE(a.removeDrift);
    EXPECT_FALSE(p.runs[1].capture.relativeLength);  // overridden by the run
    EXPECT_TRUE(p.runs[1].capture.removeDrift);
    // Written and read back: the same captures.
    writePlanXml(dir.file("back.xml"), p);
    const MeasurementPlan back = readPlanXml(dir.file("back.xml"));
    ASSERT_EQ(back.runs.size(), 2u);
    EXPECT_EQ(back.runs[0].capture, a);
    EXPECT_EQ(back.runs[1].capture, p.runs[1].capture);
    // Errors name the line.
    const auto bad = [&](const std::string& attrs, const std::string& what) {
        test::writeText(f, "<plan>\n<run name=\"a\" test=\"B-X\" LB=\"100\" RB=\"200\" ZC=\"1\" " + attrs + "/>\n</plan>\n");
        expectInputError([&] { readPlanXml(f); }, {f + ":2", what});
    };
    bad("directions=\"ccw ccw\"", "directions");
    bad("directions=\"up\"", "'up' is not ccw or cw");
    bad("feed=\"-5\"", "feed");
    bad("length-unit=\"furlong\"", "length-unit 'furlong'");
    bad("length=\"maybe\"", "length 'maybe'");
    bad("angle-column=\"a,b\"", "angle-column");
    test::writeText(f, "<plan>\n<instrument length=\"relative\"/>\n<absolute-run name=\"a\" test=\"B-Y\" LB=\"100\" "
                       "RB=\"200\" ZC=\"1\"/>\n</plan>\n");
    expectInputError([&] { readPlanXml(f); }, {f + ":3", "absolute run"});
    // A run name must be a plain file name: never DIR/../x.csv.
    for (const char* name : {"../x", "a/b", "..", ".hidden", ""}) {
        test::writeText(f, fmt::format("<plan>\n<run name=\"{}\" test=\"B-X\" LB=\"100\" RB=\"200\" ZC=\"1\"/>\n</plan>\n", name));
        expectInputError([&] { readPlanXml(f); }, {f + ":2", "run name"});
    }
    // A plan for another machine.
    test::writeText(f, "<plan machine=\"other\">\n<run name=\"a\" test=\"B-X\" LB=\"100\" RB=\"200\" ZC=\"1\"/>\n</plan>\n");
    expectInputError([&] { checkPlanMachine(readPlanXml(f), f, "multitasking"); }, {f + ":1", "'other'", "'multitasking'"});
}

TEST(MeasuredImport, MeasuredObservationsWrapRelativeRuns) {
    test::ScratchDir dir("imp-obs");
    MeasurementPlan plan;
    plan.runs = {cRadial(), cRadial()};
    plan.runs[1].name = "C-radial-2";
    plan.runs[1].capture.relativeLength = true;
    for (const BallbarRun& r : plan.runs)
        writeTraceCsv(dir.file(r.name + ".csv"), simulate(r, 0, 359, 1), r, machine().name);
    const MeasuredRuns mr = measuredObservations(
        machine(), plan, loadPlanMeasurements(machine(), plan, dir.path.string(), MeasurementKinds::observed()));
    ASSERT_EQ(mr.observations.size(), 2u);
    ASSERT_EQ(mr.ballbar.size(), 2u);
    EXPECT_EQ(mr.observations[0]->nuisanceCount(), 0);
    EXPECT_EQ(mr.observations[1]->nuisanceCount(), 1);
    EXPECT_EQ(mr.observations[1]->size(), 360);
}

}  // namespace
}  // namespace cnccomp
