// The identification façade (src/app/identify.hpp) called directly, without the executable: its options checked
// before any file is read, its registry of methods, its summary. Oracles: the simulation's truth (round trip: traces
// simulated from known deviations are identified back), and the library's own closed form on the same traces.
#include <gtest/gtest.h>

#include <filesystem>

#include "app/identify.hpp"
#include "app/identify_registry.hpp"
#include "cnccomp/closed_form.hpp"
#include "cnccomp/eccentricity.hpp"
#include "cnccomp/error.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "cnccomp/io/trace_csv.hpp"
#include "cnccomp/kinematics.hpp"
#include "test_support.hpp"

namespace cnccomp {
using namespace cnccomp::identification;
using namespace cnccomp::io;
using namespace cnccomp::measurement;
namespace {

const std::string kPlan = test::sourcePath("samples/plans/multitasking-six-circles.xml");
const std::string kTruth = test::sourcePath("samples/deviations/multitasking-truth.csv");

/// The plan's runs simulated on the true machine, written as the instrument files identify reads.
std::string simulateInto(const test::ScratchDir& dir, const MeasurementPlan& plan) {
    const MachineModel& m = test::multitasking();
    const Kinematics k(m, readDeviationCsv(kTruth, m));
    for (const BallbarRun& r : plan.runs) writeTraceCsv(dir.file(r.name + ".csv"), simulateRun(k, r), r, m.name);
    return dir.path.string();
}

using test::errorOf;

TEST(IdentifyFacade, TheRegistryServesEveryKindOfPlanAndNamesItsMethods) {
    for (PlanMethod k : {PlanMethod::Ballbar, PlanMethod::HeadPatterns, PlanMethod::RtestLocation, PlanMethod::RtestTables,
                         PlanMethod::Dbb5, PlanMethod::Mixed, PlanMethod::LinearCircle, PlanMethod::Sphere}) {
        const app::IdentificationMethod& m = app::identificationMethodFor(k);
        EXPECT_EQ(m.name, planMethodName(k));
        EXPECT_EQ(&app::identificationMethod(m.name), &m);
        EXPECT_TRUE(m.reads && m.check && m.run) << m.name;
    }
    EXPECT_EQ(app::identificationMethods().size(), 8u);
    // An unknown method is an error that lists the registered ones.
    const std::string e = errorOf([] { app::identificationMethod("laser-tracker"); });
    EXPECT_NE(e.find("unknown identification method 'laser-tracker'"), std::string::npos) << e;
    for (const char* n : {"ball-bar", "head-patterns", "rtest-location", "rtest-tables", "dbb5", "mixed", "sphere", "circle"})
        EXPECT_NE(e.find(n), std::string::npos) << n << ": " << e;
}

TEST(IdentifyFacade, OptionsAreTypedAndEachBadOneIsNamedWithWhatItAccepts) {
    EXPECT_EQ(app::parseSolver("lm"), SolverChoice{});
    EXPECT_EQ(app::parseSolver("levenberg-marquardt"), SolverChoice{});
    EXPECT_EQ(app::parseSolver("nlopt:LD_SLSQP"), (SolverChoice{SolverKind::Nlopt, "LD_SLSQP"}));
    EXPECT_EQ(app::solverText(app::parseSolver("nlopt:LD_SLSQP")), "nlopt:LD_SLSQP");
    std::string e = errorOf([] { app::parseSolver("gauss"); });
    EXPECT_NE(e.find("--solver 'gauss'"), std::string::npos) << e;
    EXPECT_NE(e.find("lm, or nlopt:<ALGORITHM>"), std::string::npos) << e;
    e = errorOf([] { app::parseSolver("nlopt:"); });
    EXPECT_NE(e.find("--solver 'nlopt:'"), std::string::npos) << e;
    e = errorOf([] { app::parseApproach("guess"); });
    EXPECT_NE(e.find("--method 'guess' (least-squares, formulas)"), std::string::npos) << e;
    EXPECT_EQ(app::parseApproach("closed-form"), app::Approach::Formulas);
    e = errorOf([] { app::parseObserve("centres"); });
    EXPECT_NE(e.find("--observe 'centres' (traces, eccentricity)"), std::string::npos) << e;

    const auto bad = [](auto change) {
        app::IdentificationOptions o;
        change(o);
        return errorOf([&] { app::validateOptions(o); });
    };
    EXPECT_EQ(bad([](app::IdentificationOptions&) {}), "");
    e = bad([](app::IdentificationOptions& o) { o.solver = {SolverKind::Nlopt, "NOT_AN_ALGORITHM"}; });
    EXPECT_NE(e.find("--solver nlopt:NOT_AN_ALGORITHM: unknown NLopt algorithm"), std::string::npos) << e;
    e = bad([](app::IdentificationOptions& o) { o.maxIterations = 0; });
    EXPECT_NE(e.find("--max-iterations 0"), std::string::npos) << e;
    e = bad([](app::IdentificationOptions& o) { o.rankTolerance = 2; });
    EXPECT_NE(e.find("--rank-tolerance 2: rank tolerance must be in (0, 1)"), std::string::npos) << e;
    e = bad([](app::IdentificationOptions& o) { o.monteCarlo = -1; });
    EXPECT_NE(e.find("--monte-carlo -1"), std::string::npos) << e;
    e = bad([](app::IdentificationOptions& o) { o.refine = 21; });
    EXPECT_NE(e.find("--refine takes 0..20"), std::string::npos) << e;
    e = bad([](app::IdentificationOptions& o) { o.bounds = "dxCZ=5"; });
    EXPECT_NE(e.find("--bounds item 'dxCZ=5': expected NAME=LOWER:UPPER"), std::string::npos) << e;
    e = bad([](app::IdentificationOptions& o) { o.bounds = "dxCZ=-5:5"; });
    EXPECT_NE(e.find("bounds need a bounded solver: --solver nlopt:<ALGORITHM>"), std::string::npos) << e;
    // Names are checked against the machine.
    e = errorOf([] { app::parseBounds(test::multitasking(), "EQ7Q=-1:1"); });
    EXPECT_NE(e.find("--bounds: unknown deviation 'EQ7Q'"), std::string::npos) << e;
    e = errorOf([] { app::parseBounds(test::multitasking(), "dxCZ=5:-5"); });
    EXPECT_NE(e.find("lower exceeds upper"), std::string::npos) << e;
}

TEST(IdentifyFacade, BadOptionsFailBeforeAnyTraceIsRead) {
    test::ScratchDir dir("facade-early");  // empty: every trace file is missing
    const MeasurementPlan plan = readPlanXml(kPlan);
    app::IdentificationOptions o;
    o.traces = dir.path.string();
    o.solver = {SolverKind::Nlopt, "NOT_AN_ALGORITHM"};
    std::string e = errorOf([&] { app::identify(test::multitasking(), &plan, o); });
    EXPECT_NE(e.find("unknown NLopt algorithm 'NOT_AN_ALGORITHM'"), std::string::npos) << e;
    EXPECT_EQ(e.find(".csv"), std::string::npos) << e;
    o.solver = {};
    o.params = "dxCZ,EQ7Q";
    e = errorOf([&] { app::identify(test::multitasking(), &plan, o); });
    EXPECT_NE(e.find("unknown deviation 'EQ7Q'"), std::string::npos) << e;
    // With good options, the missing file is what is reported.
    o.params.clear();
    e = errorOf([&] { app::identify(test::multitasking(), &plan, o); });
    EXPECT_NE(e.find(".csv"), std::string::npos) << e;
}

// Converted from IdentifyCli (it tested the identification, not the command line).
TEST(IdentifyFacade, UnidentifiableRequestIsReportedByName) {
    test::ScratchDir dir("facade-unid");
    const MeasurementPlan plan = readPlanXml(test::sourcePath("samples/plans/lsq-multitasking-b-runs.xml"));
    app::IdentificationOptions o;
    o.traces = simulateInto(dir, plan);
    o.params = "dzBT,gXB,dxCZ,dyCZ,aCZ,bCZ";
    const app::IdentificationSummary s = app::identify(test::multitasking(), &plan, o);
    EXPECT_EQ(s.method, "ball-bar");
    ASSERT_TRUE(s.report);
    ASSERT_EQ(s.report->unobservable.size(), 4u);
    EXPECT_FALSE(s.report->parameters[s.report->find("EX0C")].identified);
    EXPECT_FALSE(s.report->parameters[s.report->find("EB0C")].identified);
    const std::string full = s.fullReport();
    EXPECT_NE(full.find("EX0C           unidentified"), std::string::npos) << full;
    EXPECT_NE(full.find("warning: 4 of 6 unknowns are not identifiable"), std::string::npos) << full;
    EXPECT_NE(full.find(s.briefReport()), std::string::npos);
    EXPECT_NE(s.briefReport().find("identified 2 of 6 requested deviations"), std::string::npos) << s.briefReport();
    const MachineModel& m = test::multitasking();
    EXPECT_TRUE(s.deviations.present[m.deviationIndex("gXB")]);
    EXPECT_FALSE(s.deviations.present[m.deviationIndex("dxCZ")]);  // no meaningless value
}

// Converted from IdentifyCli.ClosedFormStillWorksExactly.
TEST(IdentifyFacade, FormulasGiveTheLibrarysClosedForm) {
    test::ScratchDir dir("facade-cf");
    const MeasurementPlan plan = readPlanXml(kPlan);
    app::IdentificationOptions o;
    o.traces = simulateInto(dir, plan);
    o.approach = app::Approach::Formulas;
    const app::IdentificationSummary s = app::identify(test::multitasking(), &plan, o);
    const MachineModel& m = test::multitasking();
    const DeviationSet lib = identifyClosedForm(m, eccentricitiesFromTraces(m, plan.runs, readRunTraces(o.traces, plan.runs)));
    EXPECT_EQ(formatDeviationCsv(s.deviations), formatDeviationCsv(lib));
    EXPECT_TRUE(s.formulas);
    EXPECT_FALSE(s.report);
    EXPECT_EQ(s.resultReport(), "");
    // Least-squares options do not apply to the formulas, and say so before any file is read.
    o.traces = (dir.path / "none").string();
    o.params = "dxCZ";
    const std::string e = errorOf([&] { app::identify(m, &plan, o); });
    EXPECT_NE(e.find("do not apply"), std::string::npos) << e;
}

}  // namespace
}  // namespace cnccomp
