// Measured data through the executable, and "no silent wrong answer": identify on time-sampled two-direction files
// with overshoot and decimal comma recovers the truth; swapped files, a plan for another machine, a run name that
// would leave the output folder, a deviation given twice, an unescaped machine name: each a clear error or a correct
// round trip. Also compare's missing list, --version and the all-or-nothing output set.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <filesystem>
#include <fstream>
#include <regex>

#include "cnccomp/error.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "cnccomp/io/output_set.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "cnccomp/io/json.hpp"
#include "cnccomp/io/report_json.hpp"
#include "cnccomp/io/trace_import.hpp"
#include "cnccomp/version.hpp"
#include "test_support.hpp"

namespace cnccomp {
using namespace cnccomp::io;
using namespace cnccomp::measurement;
namespace {
namespace fs = std::filesystem;

const std::string kMachine = test::sourcePath("samples/machines/multitasking.xml");
const std::string kPlan = test::sourcePath("samples/plans/multitasking-six-circles.xml");
const std::string kTruth = test::sourcePath("samples/deviations/multitasking-truth.csv");


std::string simulateInto(const test::ScratchDir& dir, const std::string& plan = kPlan) {
    const std::string traces = dir.file("traces");
    const auto r = test::runCli("simulate --machine " + kMachine + " --plan " + plan + " --deviations " + kTruth + " --out " + traces);
    EXPECT_EQ(r.exitCode, 0) << r.out;
    return traces;
}

TEST(MeasuredCli, TimeSampledBothDirectionsRelativeInstrumentRecoverTheTruth) {
    test::ScratchDir dir("mcli-time");
    // The six-circle plan as a real session would record it: 1000 mm/min, 5° overshoot, CCW then CW, a relative
    // transducer (unknown zero per run), exported as ms;mm with decimal comma.
    MeasurementPlan plan = readPlanXml(kPlan);
    for (BallbarRun& r : plan.runs) {
        r.capture.feed = 1000;
        r.capture.overshootDeg = 5;  // B travels ±185°
        r.capture.passes = {+1, -1};
        r.capture.timeColumn = "Zeit";
        r.capture.lengthColumn = "Abweichung";
        r.capture.lengthUnit = 1.0;
        r.capture.timeUnit = 1e-3;
        r.capture.relativeLength = true;
    }
    writePlanXml(dir.file("plan.xml"), plan);
    fs::create_directories(dir.file("traces"));
    const MachineModel& m = test::multitasking();
    const Kinematics k(m, readDeviationCsv(kTruth, m));
    for (size_t i = 0; i < plan.runs.size(); ++i) {
        const BallbarRun& r = plan.runs[i];
        const double lo = std::min(r.startDeg, r.endDeg), hi = std::max(r.startDeg, r.endDeg);
        const double omega = r.capture.feed / 60.0 / linearPathRadius(r) / kDeg;  // deg/s
        std::string csv = "Zeit;Abweichung\n";
        for (int pass = 0; pass < 2; ++pass) {
            BallbarRun sweep = r;
            sweep.capture = {};
            sweep.startDeg = pass == 0 ? lo - 5 : hi + 5;
            sweep.endDeg = pass == 0 ? hi + 5 : lo - 5;
            sweep.stepDeg = pass == 0 ? 0.5 : -0.5;
            const BallbarTrace t = simulateRun(k, sweep);
            for (size_t s = 0; s < t.dL.size(); ++s) {
                std::string time = fmt::format("{:.4f}", std::abs(t.angleDeg[s] - sweep.startDeg) / omega * 1e3);
                std::string len = fmt::format("{:.8f}", t.dL[s] + (12.0 + 7.0 * static_cast<double>(i)) * kUm);
                for (std::string* c : {&time, &len}) std::replace(c->begin(), c->end(), '.', ',');
                csv += time + ";" + len + "\n";
            }
        }
        test::writeText(dir.file("traces/" + r.name + ".csv"), csv);
    }
    const auto r = test::runCli("identify --machine " + kMachine + " --plan " + dir.file("plan.xml") + " --traces " +
                                dir.file("traces") + " --out " + dir.file("d.csv") + " --report " + dir.file("r.json"));
    ASSERT_EQ(r.exitCode, 0) << r.out;
    EXPECT_NE(r.out.find("ISO 230-4"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("C-radial.dL0"), std::string::npos) << r.out;
    // The per-run offsets take the constant part of ΔL: a deviation that only shifted a run's mean would be confounded
    // with them and would have to be named, never reported as a value.
    const MachineModel& mm = test::multitasking();
    const DeviationSet id = readDeviationCsv(dir.file("d.csv"), mm), t = readDeviationCsv(kTruth, mm);
    int compared = 0;
    for (size_t i = 0; i < mm.deviations.size(); ++i) {
        const DeviationDef& d = mm.deviations[i];
        if (!id.present[i]) {
            EXPECT_NE(r.out.find(d.name + std::string(14 - d.name.size(), ' ') + " " + d.alias), std::string::npos);
            continue;
        }
        ++compared;
        EXPECT_NEAR(id.values[d.offset], t.values[d.offset], d.isAngle() ? 1e-3 * kArcsec : 1e-3 * kUm) << d.name;
    }
    EXPECT_EQ(compared, 13) << r.out;  // here the runs tell every offset from every deviation
    // The offsets added to the files come back as the runs' dL0 (12 + 7·i µm).
    const Json j = readJsonFile(dir.file("r.json"));
    int offsets = 0;
    for (const Json& p : j["parameters"].array) {
        const std::string& n = p["name"].string;
        for (size_t i = 0; i < plan.runs.size(); ++i)
            if (n == plan.runs[i].name + ".dL0") {
                EXPECT_NEAR(p["value"].num(), 12.0 + 7.0 * static_cast<double>(i), 1e-3) << n;
                ++offsets;
            }
    }
    EXPECT_EQ(offsets, 6);
}

TEST(MeasuredCli, SwappedTraceFilesAreRefusedNotFitted) {
    test::ScratchDir dir("mcli-swap");
    const std::string traces = simulateInto(dir);
    // The issue's case: two files of the same sweep swapped.
    fs::rename(traces + "/C-radial.csv", traces + "/tmp.csv");
    fs::rename(traces + "/C-radial-ZC2.csv", traces + "/C-radial.csv");
    fs::rename(traces + "/tmp.csv", traces + "/C-radial-ZC2.csv");
    const auto r = test::runCli("identify --machine " + kMachine + " --plan " + kPlan + " --traces " + traces + " --out " +
                                dir.file("d.csv"));
    EXPECT_EQ(r.exitCode, 2) << r.out;
    EXPECT_NE(r.out.find("C-radial.csv:2: the file says run 'C-radial-ZC2'"), std::string::npos) << r.out;
    EXPECT_FALSE(fs::exists(dir.file("d.csv")));
    // Closed form reads the same files the same way.
    const auto cf = test::runCli("identify --method closed-form --machine " + kMachine + " --plan " + kPlan + " --traces " +
                                 traces + " --out " + dir.file("cf.csv"));
    EXPECT_EQ(cf.exitCode, 2) << cf.out;
    EXPECT_NE(cf.out.find("another run"), std::string::npos) << cf.out;
}

TEST(MeasuredCli, PlanForAnotherMachineIsRefused) {
    test::ScratchDir dir("mcli-machine");
    const std::string traces = simulateInto(dir);
    std::string text = test::readText(kPlan);
    text.replace(text.find("machine=\"multitasking\""), 22, "machine=\"table-table-ac\"");
    test::writeText(dir.file("p.xml"), text);
    const auto r = test::runCli("identify --machine " + kMachine + " --plan " + dir.file("p.xml") + " --traces " + traces +
                                " --out " + dir.file("d.csv"));
    EXPECT_EQ(r.exitCode, 2) << r.out;
    EXPECT_NE(r.out.find(dir.file("p.xml") + ":4: this plan was made for machine 'table-table-ac'"), std::string::npos) << r.out;
}

TEST(MeasuredCli, RunNameCannotLeaveTheOutputFolder) {
    test::ScratchDir dir("mcli-escape");
    fs::create_directories(dir.file("out"));
    test::writeText(dir.file("p.xml"), "<plan>\n<run name=\"../x\" test=\"B-X\" LB=\"100\" RB=\"360\" ZC=\"300\"/>\n</plan>\n");
    for (const char* cmd : {"simulate"}) {
        const auto r = test::runCli(std::string(cmd) + " --machine " + kMachine + " --plan " + dir.file("p.xml") + " --out " +
                                    dir.file("out"));
        EXPECT_EQ(r.exitCode, 2) << r.out;
        EXPECT_NE(r.out.find("p.xml:2"), std::string::npos) << r.out;
        EXPECT_NE(r.out.find("run name '../x'"), std::string::npos) << r.out;
    }
    EXPECT_FALSE(fs::exists(dir.file("x.csv")));
}

TEST(MeasuredCli, DeviationGivenTwiceIsAnError) {
    test::ScratchDir dir("mcli-dup");
    test::writeText(dir.file("d.csv"), "name,alias,value,unit\nEB0B,,9,arcsec\nEX0C,,1,um\n,bXB,12,arcsec\n");
    const auto r = test::runCli("compare --machine " + kMachine + " --truth " + kTruth + " --estimate " + dir.file("d.csv"));
    EXPECT_EQ(r.exitCode, 2) << r.out;
    EXPECT_NE(r.out.find("d.csv:4: EB0B is given twice (first on line 2)"), std::string::npos) << r.out;
}

TEST(MeasuredCli, CompareListsDeviationsMissingFromTheEstimate) {
    test::ScratchDir dir("mcli-compare");
    test::writeText(dir.file("d.csv"), "name,alias,value,unit\nEB0B,,9,arcsec\nEX0C,,1,um\n");
    const auto r = test::runCli("compare --machine " + kMachine + " --truth " + kTruth + " --estimate " + dir.file("d.csv"));
    ASSERT_EQ(r.exitCode, 0) << r.out;
    EXPECT_NE(r.out.find("over the 2 deviations in both sets"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("missing from the estimate (11 of the truth's deviations, not compared): EX0C1 (dxBT), EZ0C1 (dzBT)"),
              std::string::npos)
        << r.out;
    EXPECT_NE(r.out.find("EC0Y (gXY)"), std::string::npos) << r.out;
}

TEST(MeasuredCli, PlanWithAMachineNamedWithMarkupCharactersReadsBack) {
    test::ScratchDir dir("mcli-escape-xml");
    std::string text = test::readText(kMachine);
    const std::string from = "<machine name=\"multitasking\"";
    text.replace(text.find(from), from.size(), "<machine name=\"A&amp;B &lt;5&gt; &quot;x&quot; 'y'\"");
    test::writeText(dir.file("m.xml"), text);
    ASSERT_EQ(readMachineXml(dir.file("m.xml")).name, "A&B <5> \"x\" 'y'");
    const auto r = test::runCli("plan --machine " + dir.file("m.xml") + " --identify dxBT,dzBT --out " + dir.file("p.xml"));
    ASSERT_EQ(r.exitCode, 0) << r.out;
    const MeasurementPlan p = readPlanXml(dir.file("p.xml"));  // valid XML
    EXPECT_EQ(p.machine, "A&B <5> \"x\" 'y'");
    // And the traces written for it name the machine so that they read back for it.
    const auto s = test::runCli("simulate --machine " + dir.file("m.xml") + " --plan " + dir.file("p.xml") + " --out " +
                                dir.file("t"));
    ASSERT_EQ(s.exitCode, 0) << s.out;
    const auto id = test::runCli("identify --machine " + dir.file("m.xml") + " --plan " + dir.file("p.xml") + " --traces " +
                                 dir.file("t") + " --params dxBT,dzBT --out " + dir.file("d.csv"));
    EXPECT_EQ(id.exitCode, 0) << id.out;
}

TEST(MeasuredCli, VersionIsTheProjectVersion) {
    const auto r = test::runCli("--version");
    EXPECT_EQ(r.exitCode, 0) << r.out;
    // Independent of version.hpp: the version in CMakeLists.txt.
    std::smatch mv;
    const std::string cmake = test::readText(test::sourcePath("CMakeLists.txt"));
    ASSERT_TRUE(std::regex_search(cmake, mv, std::regex(R"(project\(cnccomp VERSION ([0-9.]+))")));
    EXPECT_EQ(r.out, "cnccomp " + mv[1].str() + "\n");
    EXPECT_EQ(std::string(kVersion), mv[1].str());
}

TEST(OutputSet, NothingChangesUntilCommitAndAFailureLeavesNothing) {
    test::ScratchDir dir("outset");
    test::writeText(dir.file("old.txt"), "old");
    {
        OutputSet out;
        out.makeFolder(dir.file("new/deeper"));
        out.add(dir.file("new/deeper/a.txt"), "a");
        out.add(dir.file("old.txt"), "replaced");
        EXPECT_EQ(test::readText(dir.file("old.txt")), "old");  // not yet
        EXPECT_FALSE(fs::exists(dir.file("new/deeper/a.txt")));
        // No commit: the command failed.
    }
    EXPECT_EQ(test::readText(dir.file("old.txt")), "old");
    EXPECT_FALSE(fs::exists(dir.file("new")));  // the folders it made are gone
    size_t files = 0;
    for (const auto& e : fs::directory_iterator(dir.path)) files += e.is_regular_file() ? 1 : 0;
    EXPECT_EQ(files, 1u);  // no temporary file left
    {
        OutputSet out({dir.file("old.txt")});
        out.makeFolder(dir.file("new"));
        out.add(dir.file("new/a.txt"), "a");
        out.add(dir.file("new/b.txt"), [](std::ostream& o) { o << "b"; });
        EXPECT_THROW(out.add(dir.file("old.txt"), "x"), InputError);       // an input
        EXPECT_THROW(out.add(dir.file("new/a.txt"), "again"), InputError);  // twice
        EXPECT_THROW(out.add(dir.path.string(), "x"), InputError);         // a folder
        EXPECT_THROW(out.add(dir.file("missing/c.txt"), "x"), InputError);  // no such folder
        EXPECT_THROW(out.add(dir.file("new/c.txt"), [](std::ostream&) { throw ModelError("fails half way"); }), ModelError);
        out.commit();
    }
    EXPECT_EQ(test::readText(dir.file("new/a.txt")), "a");
    EXPECT_EQ(test::readText(dir.file("new/b.txt")), "b");
    EXPECT_FALSE(fs::exists(dir.file("new/c.txt")));
    EXPECT_EQ(test::readText(dir.file("old.txt")), "old");
    EXPECT_EQ(OutputSet::fileIn("d", "run.csv"), "d/run.csv");
    for (const char* bad : {"../x", "a/b", "a\\b", "..", ".", ".x", "", "a\nb"}) EXPECT_THROW(OutputSet::fileIn("d", bad), InputError) << bad;
}

TEST(OutputSet, IdentifyWritesItsOutputsAllOrNothing) {
    test::ScratchDir dir("outset-identify");
    const std::string traces = simulateInto(dir);
    // The report cannot be written (a folder stands there): the deviation file must not appear either.
    fs::create_directories(dir.file("r.json"));
    const auto r = test::runCli("identify --machine " + kMachine + " --plan " + kPlan + " --traces " + traces + " --out " +
                                dir.file("d.csv") + " --report " + dir.file("r.json"));
    EXPECT_EQ(r.exitCode, 2) << r.out;
    EXPECT_NE(r.out.find("not a regular file"), std::string::npos) << r.out;
    EXPECT_FALSE(fs::exists(dir.file("d.csv")));
}

}  // namespace
}  // namespace cnccomp
