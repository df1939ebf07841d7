// The identification's outputs (src/app/identify_outputs.hpp) called directly, without the executable: the requests
// checked before anything is written, all or nothing when a later output fails, --merge into an existing set. The
// summaries come from the façade (app::identify) on traces simulated from the sample truth.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <functional>
#include <string>

#include "app/identify.hpp"
#include "app/identify_outputs.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "cnccomp/io/report_json.hpp"
#include "cnccomp/io/trace_csv.hpp"
#include "cnccomp/kinematics.hpp"
#include "test_support.hpp"

namespace cnccomp {
using namespace cnccomp::io;
using namespace cnccomp::measurement;
namespace {

namespace fs = std::filesystem;

const std::string kPlan = test::sourcePath("samples/plans/multitasking-six-circles.xml");
const std::string kTruth = test::sourcePath("samples/deviations/multitasking-truth.csv");
const std::string kMachine = test::sourcePath("samples/machines/multitasking.xml");

using test::errorOf;

/// The sample plan's runs simulated on the true machine into a folder kept for the whole test run, and the plan.
struct Simulated {
    test::ScratchDir dir{"identify-outputs-traces"};
    MeasurementPlan plan = readPlanXml(kPlan);
    Simulated() {
        const MachineModel& m = test::multitasking();
        const Kinematics k(m, readDeviationCsv(kTruth, m));
        for (const BallbarRun& r : plan.runs) writeTraceCsv(dir.file(r.name + ".csv"), simulateRun(k, r), r, m.name);
    }
};
const Simulated& simulated() {
    static const Simulated s;
    return s;
}

app::IdentificationOptions optionsOn(const Simulated& s) {
    app::IdentificationOptions o;
    o.traces = s.dir.path.string();
    return o;
}

/// Least squares (the default) on the simulated traces, computed once.
const app::IdentificationSummary& leastSquares() {
    static const app::IdentificationSummary s =
        app::identify(test::multitasking(), &simulated().plan, optionsOn(simulated()));
    return s;
}

/// Outputs in `dir` with the sample machine and plan as the inputs.
app::IdentificationOutputs outputsIn(const test::ScratchDir& dir) {
    app::IdentificationOutputs out;
    out.machineFile = kMachine;
    out.planFile = kPlan;
    out.deviations = dir.file("d.csv");
    return out;
}

app::WrittenIdentification write(const app::IdentificationOutputs& out,
                                 const app::IdentificationSummary& s = leastSquares()) {
    return app::writeIdentificationOutputs(test::multitasking(), &simulated().plan, optionsOn(simulated()), s, out);
}

// Oracle: the all-or-nothing contract of io/output_set.hpp, observed on the file system. Every request below fails
// after the deviation CSV could have been written (the summary is complete); the old d.csv must be left as it was and
// no other file may appear.
TEST(IdentifyOutputs, NothingIsWrittenWhenALaterOutputFails) {
    const test::ScratchDir dir("identify-outputs-none");
    test::writeText(dir.file("d.csv"), "old\n");
    const auto onlyTheOldFile = [&] {
        EXPECT_EQ(test::readText(dir.file("d.csv")), "old\n");
        int files = 0;
        for (const auto& e : fs::recursive_directory_iterator(dir.path)) files += e.is_regular_file() ? 1 : 0;
        EXPECT_EQ(files, 1);
    };
    // An extra output the method does not write (the ISO table of DBB5 runs, for ball-bar circles).
    app::IdentificationOutputs out = outputsIn(dir);
    out.report = dir.file("r.json");
    out.isoOut = dir.file("iso.csv");
    std::string e = errorOf([&] { write(out); });
    EXPECT_EQ(e, "--iso-out does not apply to the ball-bar method") << e;
    onlyTheOldFile();
    // Controllers and a grid belong to an HTML report, not a JSON one.
    out = outputsIn(dir);
    out.report = dir.file("r.json");
    out.reportControllers = "linuxcnc";
    e = errorOf([&] { write(out); });
    EXPECT_EQ(e, "--report-controllers and --report-grid belong to an HTML report: give --report R.html") << e;
    onlyTheOldFile();
    // The report's folder does not exist: found while staging, after the deviation CSV was staged.
    out = outputsIn(dir);
    out.report = dir.file("missing/r.json");
    e = errorOf([&] { write(out); });
    EXPECT_NE(e.find("output folder does not exist"), std::string::npos) << e;
    EXPECT_NE(e.find("missing/r.json"), std::string::npos) << e;
    onlyTheOldFile();
    // An HTML page whose map grid is not a grid: the page is built after the CSV was staged.
    out = outputsIn(dir);
    out.report = dir.file("r.html");
    out.reportGrid = "not a grid";
    e = errorOf([&] { write(out); });
    EXPECT_EQ(e, "report map grid: 'not': expected NAME=from:to:step or NAME=value") << e;
    onlyTheOldFile();
    // A formulas summary writes no least-squares report.
    app::IdentificationOptions formulas = optionsOn(simulated());
    formulas.approach = app::Approach::Formulas;
    const app::IdentificationSummary f = app::identify(test::multitasking(), &simulated().plan, formulas);
    out = outputsIn(dir);
    out.report = dir.file("r.json");
    e = errorOf([&] { write(out, f); });
    EXPECT_EQ(e, "--report: the formulas of 'ball-bar' writes no least-squares report") << e;
    onlyTheOldFile();
}

// Oracle: the rule "an output never names an input, never two outputs the same file" applied by hand to paths whose
// answer is known (a copy of the machine file, the merge base, two options naming one path). The input's content is
// compared byte for byte after the refusal.
TEST(IdentifyOutputs, AnOutputNamingAnInputIsRefused) {
    const test::ScratchDir dir("identify-outputs-inputs");
    test::writeText(dir.file("machine.xml"), test::readText(kMachine));
    app::IdentificationOutputs out = outputsIn(dir);
    out.machineFile = dir.file("machine.xml");
    out.report = dir.file("machine.xml");
    const app::IdentificationOptions o = optionsOn(simulated());
    std::string e = errorOf([&] { app::checkOutputRequests(out, o); });
    EXPECT_NE(e.find("refusing to overwrite the input file '" + dir.file("machine.xml") + "'"), std::string::npos) << e;
    e = errorOf([&] { write(out); });  // the writer checks again
    EXPECT_NE(e.find("refusing to overwrite the input file"), std::string::npos) << e;
    EXPECT_EQ(test::readText(dir.file("machine.xml")), test::readText(kMachine));
    EXPECT_FALSE(fs::exists(dir.file("d.csv")));
    // The merge base is an input too: --out cannot be it.
    test::writeText(dir.file("base.csv"), formatDeviationCsv(DeviationSet(test::multitasking())));
    const std::string base = test::readText(dir.file("base.csv"));
    out = outputsIn(dir);
    out.merge = dir.file("base.csv");
    out.deviations = dir.file("base.csv");
    e = errorOf([&] { write(out); });
    EXPECT_NE(e.find("refusing to overwrite the input file '" + dir.file("base.csv") + "'"), std::string::npos) << e;
    EXPECT_EQ(test::readText(dir.file("base.csv")), base);
    // And the other inputs (e.g. --truth) the caller names.
    out = outputsIn(dir);
    test::writeText(dir.file("truth.csv"), test::readText(kTruth));
    out.otherInputs = {dir.file("truth.csv")};
    out.anglesOut = dir.file("truth.csv");
    e = errorOf([&] { app::checkOutputRequests(out, o); });
    EXPECT_NE(e.find("refusing to overwrite the input file '" + dir.file("truth.csv") + "'"), std::string::npos) << e;
    // Never twice.
    out = outputsIn(dir);
    out.report = dir.file("d.csv");
    e = errorOf([&] { app::checkOutputRequests(out, o); });
    EXPECT_EQ(e, "--out and --report name the same file '" + dir.file("d.csv") + "'") << e;
    // The requests that need options.
    out = outputsIn(dir);
    out.profileOut = dir.file("p.csv");
    EXPECT_EQ(errorOf([&] { app::checkOutputRequests(out, o); }), "--profile-out needs --components");
    out = outputsIn(dir);
    out.volumetricOut = dir.file("v.csv");
    EXPECT_EQ(errorOf([&] { app::checkOutputRequests(out, o); }), "--volumetric-out needs --volumetric RUN");
    EXPECT_FALSE(fs::exists(dir.file("d.csv")));
}

// Oracle: the merge rule (laser_deviation.hpp, mergeDeviations) applied by hand: a deviation the identification
// determined takes the summary's value, every other one of the base keeps the base's value exactly.
TEST(IdentifyOutputs, MergeKeepsTheBasesOtherDeviations) {
    const test::ScratchDir dir("identify-outputs-merge");
    const MachineModel& m = test::multitasking();
    app::IdentificationOptions o = optionsOn(simulated());
    o.params = "dxCZ,dyCZ";  // only these two identified: the base's others must stay
    const app::IdentificationSummary s = app::identify(m, &simulated().plan, o);
    ASSERT_TRUE(s.deviations.present[m.deviationIndex("EX0C")]);
    ASSERT_FALSE(s.deviations.present[m.deviationIndex("EX0C1")]);
    DeviationSet base(m);
    base.set("EX0C", -40 * kUm);     // identified: replaced
    base.set("EX0C1", 99 * kUm);     // not identified: kept
    base.set("EC0B", 3.25 * kArcsec);  // not identified: kept
    test::writeText(dir.file("base.csv"), formatDeviationCsv(base));
    app::IdentificationOutputs out = outputsIn(dir);
    out.merge = dir.file("base.csv");
    const app::WrittenIdentification w =
        app::writeIdentificationOutputs(m, &simulated().plan, o, s, out);
    const DeviationSet d = readDeviationCsv(dir.file("d.csv"), m);
    EXPECT_NEAR(d.get("EX0C") / kUm, s.deviations.get("EX0C") / kUm, 1e-4);  // the CSV's rounding
    EXPECT_GT(std::abs(d.get("EX0C") / kUm + 40), 1.0);                       // not the base's
    EXPECT_TRUE(d.present[m.deviationIndex("EY0C")]);
    EXPECT_NEAR(d.get("EX0C1") / kUm, 99.0, 1e-9);
    EXPECT_NEAR(d.get("EC0B") / kArcsec, 3.25, 1e-9);
    EXPECT_TRUE(w.mergeLines.empty());  // neither set has a reversal value
    const std::string text = app::writtenIdentificationText(s, out, w, &simulated().plan);
    EXPECT_NE(text.find(s.briefReport() + " -> " + dir.file("d.csv") + " (merged into " + dir.file("base.csv") + ")\n"),
              std::string::npos)
        << text;
    EXPECT_EQ(test::readText(dir.file("base.csv")), formatDeviationCsv(base));  // the base itself is not touched
}

// Oracle: round trip through the library's own writers: what is committed is exactly formatDeviationCsv and
// formatReportJson of the summary, and the text names both files and carries the ISO 230-4 table of the measured runs.
TEST(IdentifyOutputs, EveryRequestedFileIsWrittenFromTheSummary) {
    const test::ScratchDir dir("identify-outputs-all");
    app::IdentificationOutputs out = outputsIn(dir);
    out.report = dir.file("r.json");
    const app::WrittenIdentification w = write(out);
    EXPECT_EQ(test::readText(dir.file("d.csv")), formatDeviationCsv(leastSquares().deviations));
    EXPECT_EQ(test::readText(dir.file("r.json")), formatReportJson(*leastSquares().report));
    ASSERT_EQ(w.runs.size(), simulated().plan.runs.size());
    const std::string text = app::writtenIdentificationText(leastSquares(), out, w, &simulated().plan);
    EXPECT_NE(text.find(" -> " + dir.file("d.csv") + ", report -> " + dir.file("r.json") + "\n"), std::string::npos) << text;
    EXPECT_NE(text.find("ISO 230-4 circular test figures"), std::string::npos) << text;
    EXPECT_NE(text.find(leastSquares().resultReport()), std::string::npos);
}

}  // namespace
}  // namespace cnccomp
