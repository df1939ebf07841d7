// `cnccomp verify`: the readings before compensation are those of the simulation (the programs as written read back
// give the same ΔL), recognising the compensation a path holds, the gate and its exit statuses, damaged files, the
// JSON report, and `cnccomp emit --plan`.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <set>

#include <fmt/format.h>

#include "cnccomp/identification/rtest_run.hpp"
#include "cnccomp/identification/tilting_head_errors.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "cnccomp/io/json.hpp"
#include "cnccomp/io/report_json.hpp"
#include "app/verify.hpp"
#include "app/verify_sources.hpp"
#include "test_deviation_text.hpp"
#include "test_support.hpp"
#include "cnccomp/identification/dbb5_run.hpp"

namespace cnccomp {
using namespace cnccomp::identification;
using namespace cnccomp::io;
using namespace cnccomp::measurement;
namespace {

struct Sample {
    const char* plan;
    const char* machine;
    const char* truth;
};
constexpr Sample kSamples[] = {
    {"multitasking-six-circles.xml", "multitasking", "multitasking-truth.csv"},
    {"lsq-multitasking-planned.xml", "multitasking", "multitasking-truth.csv"},
    {"tilting-head-b-patterns.xml", "tilting-head-b", "tilting-head-b-truth.csv"},
    {"table-table-ac-rtest.xml", "table-table-ac", "table-table-ac-truth.csv"},
    {"table-table-ac-kinematic.xml", "table-table-ac", "table-table-ac-truth.csv"},
    {"dbb5-table-table-ac.xml", "table-table-ac", "dbb5-truth.csv"},
};

std::string src(const std::string& rel) { return test::sourcePath(rel); }

TEST(Verify, ReadingsBeforeCompensationAreTheSimulationsForEveryPlanKind) {
    // The commands come from the test programs read back (6 decimals); the oracle is simulate / simulate-runs on the
    // same machine with the plan's own commands.
    for (const Sample& s : kSamples) {
        const MachineModel m = readMachineXml(src(std::string("samples/machines/") + s.machine + ".xml"));
        const MeasurementPlan plan = readPlanXml(src(std::string("samples/plans/") + s.plan));
        const DeviationSet truth = readDeviationCsv(src(std::string("samples/deviations/") + s.truth), m);
        app::VerifyCompensation comp;
        comp.kind = app::VerifyCompensation::Kind::Deviations;
        comp.model = app::idealCompensation(m, truth);
        app::VerifyOptions o;
        o.volumetricPerAxis = 2;
        const app::VerifyResult r = app::verify(m, plan, truth, "truth", comp, o);
        ASSERT_EQ(r.runs.size(), plan.runCount()) << s.plan;
        const Kinematics k(m, truth);
        size_t i = 0;
        const auto compare = [&](const BallbarTrace& want) {
            const app::VerifyRun& run = r.runs[i++];
            for (const app::VerifyPass& p : run.passes) {
                ASSERT_EQ(p.before.dL.size(), want.dL.size()) << s.plan << " " << run.name;
                for (size_t j = 0; j < want.dL.size(); ++j) {
                    // The pass may run backwards: find the sample by its angle.
                    const auto at = std::find(want.angleDeg.begin(), want.angleDeg.end(), p.before.angleDeg[j]);
                    ASSERT_NE(at, want.angleDeg.end());
                    EXPECT_NEAR(p.before.dL[j], want.dL[static_cast<size_t>(at - want.angleDeg.begin())], 2e-6)
                        << s.plan << " " << run.name << " " << p.label << " at " << p.before.angleDeg[j];
                }
                // The ideal compensation with the truth itself leaves only the programs' rounding.
                EXPECT_LT(p.spanAfter, 0.01 * kUm) << s.plan << " " << run.name;
            }
        };
        for (const BallbarRun& b : plan.runs) compare(simulateRun(k, b));
        for (const BallbarRun& b : plan.absoluteRuns) compare(simulateAbsoluteRun(k, b));
        for (const Dbb5Run& d : plan.dbb5Runs) compare(simulateDbb5(k, d));
        for (const RtestRun& t : plan.rtestRuns) {
            const RtestTrace want = simulateRtest(k, t);
            const app::VerifyRun& run = r.runs[i++];
            for (const app::VerifyPass& p : run.passes)
                for (size_t j = 0; j < p.displacementBefore.size(); ++j)
                    EXPECT_LT((p.displacementBefore[j] - want.d[static_cast<size_t>(p.before.angleDeg[j])]).norm(), 2e-6)
                        << s.plan << " " << run.name;
        }
        EXPECT_GT(r.residualBefore, 1 * kUm) << s.plan;
    }
}

TEST(Verify, IsoFiguresEccentricityAndJsonOfAnIdealCompensation) {
    test::ScratchDir dir("verify-json");
    const std::string m = src("samples/machines/multitasking.xml"), p = src("samples/plans/multitasking-six-circles.xml"),
                      t = src("samples/deviations/multitasking-truth.csv");
    const auto r = test::runCli("verify --machine " + m + " --plan " + p + " --truth " + t + " --compensation " + t +
                                " --max-residual-um 0.05 --json " + dir.file("v.json"));
    ASSERT_EQ(r.exitCode, 0) << r.out;
    EXPECT_NE(r.out.find("verification passed"), std::string::npos) << r.out;
    const Json j = readJsonFile(dir.file("v.json"));
    EXPECT_EQ(j["schema"].string, "cnccomp-verify/1");
    EXPECT_EQ(j["passed"].boolean, true);
    ASSERT_EQ(j["runs"].array.size(), 6u);
    const Json& cRadial = j["runs"][3];
    EXPECT_EQ(cRadial["name"].string, "C-radial");
    ASSERT_EQ(cRadial["passes"].array.size(), 2u);
    EXPECT_EQ(cRadial["passes"][0]["direction"].string, "CW");
    EXPECT_EQ(cRadial["passes"][1]["direction"].string, "CCW");
    EXPECT_EQ(cRadial["passes"][0]["dL_before_um"].array.size(), 360u);
    // [MultiTasking] Table 5 sign convention: the C-radial eccentricity before is the one `simulate` + eccentricities give.
    const MachineModel& mm = test::multitasking();
    const MeasurementPlan plan = readPlanXml(p);
    const DeviationSet truth = readDeviationCsv(t, mm);
    const Vec3 e = traceEccentricity(mm, plan.runs[3], simulateRun(Kinematics(mm, truth), plan.runs[3]));
    EXPECT_NEAR(cRadial["passes"][0]["eccentricity_before_um"][0].num(), e.x() / kUm, 1e-3);
    EXPECT_NEAR(cRadial["passes"][0]["eccentricity_before_um"][1].num(), e.y() / kUm, 1e-3);
    EXPECT_EQ(cRadial["passes"][0]["eccentricity_before_um"][2].type, Json::Type::Null);
    EXPECT_GT(cRadial["passes"][0]["iso_before"]["circular_deviation_G_um"].num(), 0.5);
    EXPECT_LT(cRadial["passes"][0]["iso_after"]["circular_deviation_G_um"].num(), 0.01);
    EXPECT_LT(j["residual_um"].num(), 0.01);
    EXPECT_GT(j["volumetric"]["max_before_um"].num(), 10.0);
    EXPECT_LT(j["volumetric"]["max_after_um"].num(), 0.01);
}

TEST(Verify, BackendRecognisedFromTheFilesAndUnknownFoldersRefused) {
    test::ScratchDir dir("verify-recognise");
    const MachineModel& m = test::multitasking();
    const DeviationSet d = readDeviationCsv(src("samples/deviations/multitasking-truth.csv"), m);
    for (const controllers::Backend* b : controllers::backends()) {
        const auto files = b->emit({m, d, "d.csv", "2024-01-01"}).files;
        const controllers::Backend* found = controllers::recognizeBackend(files);
        ASSERT_TRUE(found) << b->name();
        EXPECT_EQ(found->name(), b->name());
    }
    EXPECT_EQ(controllers::recognizeBackend({{"notes.txt", "x"}}), nullptr);
    // Through the CLI: an emit folder without --controller; a folder of anything else is refused by name.
    const std::string mf = src("samples/machines/multitasking.xml"), p = src("samples/plans/multitasking-six-circles.xml"),
                      t = src("samples/deviations/multitasking-truth.csv");
    auto r = test::runCli("emit --controller fanuc-30i --machine " + mf + " --deviations " + t + " --out " + dir.file("f"));
    ASSERT_EQ(r.exitCode, 0) << r.out;
    r = test::runCli("verify --machine " + mf + " --plan " + p + " --truth " + t + " --compensation " + dir.file("f"));
    // No gate given: 1 only where the files make the machine worse than none, which the first line then says.
    ASSERT_EQ(r.exitCode, r.out.rfind("COMPENSATION MAKES THE MACHINE WORSE", 0) == 0 ? 1 : 0) << r.out;
    EXPECT_NE(r.out.find("fanuc-30i files in"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("EA0C1"), std::string::npos) << "the NOT-compensated list of the files is printed";
    std::filesystem::create_directories(dir.file("other"));
    test::writeText(dir.file("other/readme.txt"), "hello\n");
    r = test::runCli("verify --machine " + mf + " --plan " + p + " --truth " + t + " --compensation " + dir.file("other"));
    EXPECT_EQ(r.exitCode, 2) << r.out;
    EXPECT_NE(r.out.find("neither controller files"), std::string::npos) << r.out;
    r = test::runCli("verify --machine " + mf + " --plan " + p + " --truth " + t + " --compensation " + dir.file("f") +
                     " --controller okuma");
    EXPECT_EQ(r.exitCode, 2) << r.out;
    EXPECT_NE(r.out.find("unknown controller 'okuma'"), std::string::npos) << r.out;
    // Without --truth a folder needs the identified set it was made from.
    r = test::runCli("verify --machine " + mf + " --plan " + p + " --compensation " + dir.file("f"));
    EXPECT_EQ(r.exitCode, 2) << r.out;
    EXPECT_NE(r.out.find("--identified"), std::string::npos) << r.out;
    r = test::runCli("verify --machine " + mf + " --plan " + p + " --compensation " + dir.file("f") + " --identified " + t);
    EXPECT_EQ(r.exitCode, r.out.rfind("COMPENSATION MAKES THE MACHINE WORSE", 0) == 0 ? 1 : 0) << r.out;  // as above
    EXPECT_NE(r.out.find("identified machine"), std::string::npos) << r.out;
}

TEST(Verify, ADamagedFileFailsTheGateWithExitStatusOne) {
    // ISG files of the tilting head: the B tables are rows of volcomp.csv. Emitted from the truth they pass a 0.1 µm
    // gate; one sign flipped or one row missing does not.
    test::ScratchDir dir("verify-damaged");
    const std::string m = src("samples/machines/tilting-head-b.xml"), p = src("samples/plans/tilting-head-b-patterns.xml"),
                      t = src("samples/deviations/tilting-head-b-truth.csv");
    auto r = test::runCli("emit --controller isg --machine " + m + " --deviations " + t + " --out " + dir.file("good"));
    ASSERT_EQ(r.exitCode, 0) << r.out;
    const auto gate = [&](const std::string& folder) {
        return test::runCli("verify --machine " + m + " --plan " + p + " --truth " + t + " --compensation " + folder +
                            " --max-residual-um 0.1 --json " + dir.file(folder.substr(folder.rfind('/') + 1) + ".json"));
    };
    r = gate(dir.file("good"));
    EXPECT_EQ(r.exitCode, 0) << r.out;
    const std::string csv = test::readText(dir.file("good/volcomp.csv"));
    const std::string row = "\n45.000000 0.000621320";
    ASSERT_NE(csv.find(row), std::string::npos) << csv;
    std::filesystem::create_directories(dir.file("sign"));
    std::filesystem::copy(dir.file("good/volcomp.lis"), dir.file("sign/volcomp.lis"));
    std::string flipped = csv;
    flipped.replace(flipped.find(row), row.size(), "\n45.000000 -0.000621320");
    test::writeText(dir.file("sign/volcomp.csv"), flipped);
    r = gate(dir.file("sign"));
    EXPECT_EQ(r.exitCode, 1) << r.out;
    EXPECT_NE(r.out.find("above --max-residual-um"), std::string::npos) << r.out;
    EXPECT_EQ(readJsonFile(dir.file("sign.json"))["passed"].boolean, false) << "the report is written before the gate fails";
    std::filesystem::create_directories(dir.file("row"));
    std::filesystem::copy(dir.file("good/volcomp.lis"), dir.file("row/volcomp.lis"));
    std::string missing = csv;
    const size_t at = missing.find(row) + 1;
    missing.erase(at, missing.find('\n', at) - at + 1);
    test::writeText(dir.file("row/volcomp.csv"), missing);
    r = gate(dir.file("row"));
    EXPECT_EQ(r.exitCode, 1) << r.out;
}

TEST(Verify, EveryBackendsDamagedFilesFailTheGate) {
    // Oracle: the simulation on the true machine (R-test of the A/C cradle). For every backend the files it writes pass a
    // 0.1 um gate; one value that matters with its sign flipped fails it with exit status 1; one row missing fails it
    // too (exit 1), or, where the format makes a missing row a syntax error, is refused with file:line (exit 2).
    // The damaged values move an axis line relative to the workpiece datum. (A value that moves the datum with the axis
    // line, e.g. the first table axis' offset or a shift along the A axis, is a pure datum shift: no relative
    // measurement sees it, the volumetric figure does; ControllerHeidenhain.ATransRowThatShiftsTheDatum... shows one.)
    // ISG: Verify.ADamagedFileFailsTheGateWithExitStatusOne.
    struct Case {
        const char* backend;
        bool claimedTruth;  ///< truth restricted to what the backend compensates of it (EY0A EZ0A EX0C EY0C)
        const char* signFile;
        const char* signFrom;  ///< text replaced by signTo: one value's sign flipped
        const char* signTo;
        const char* rowFile;
        const char* rowKey;    ///< text on the line that goes missing
        const char* rowError;  ///< empty: the gate fails (1); else the file:line message (2)
    };
    const Case cases[] = {
        {"heidenhain-tnc", false, "TABLE_TABLE_AC.TAB", "Trans     Y     -0.002000000", "Trans     Y     0.002000000 ",
         "TABLE_TABLE_AC.TAB", "Trans     Y     -0.002000000", "TABLE_TABLE_AC.TAB:19: NR '17': expected 16"},
        {"siemens-840d", false, "CNCCOMP_KINCHAIN.SPF", "$NK_OFF_DIR[9,1]=-0.002000000", "$NK_OFF_DIR[9,1]=0.002000000",
         "NC_CEC.INI", "$AN_CEC[0,5]=", "NC_CEC.INI:32: CEC table 0: (MAX-MIN)/STEP+1 = 201 points expected, 200 given"},
        {"fanuc-30i", true, "CNCCOMP.PRM", "N19702Q1L1P-0.0680", "N19702Q1L1P0.0680", "CNCCOMP.PRM", "N19704Q1L1P",
         "CNCCOMP.PRM:36: parameter 19704 is missing"},
        // LinuxCNC's component route (its default): the deviation pins of cnccomp-kins.hal.
        // (EY0C: the plan's R-test runs see it; EY0A, EX0C and EZ0A shift nothing these relative readings see.)
        {"linuxcnc", true, "cnccomp-kins.hal", "setp cnccomp_kins.dev.ey0c -0.002", "setp cnccomp_kins.dev.ey0c 0.002",
         "cnccomp-kins.hal", "setp cnccomp_kins.dev.ey0a", "pin cnccomp_kins.dev.ey0a is not set"},
        {"generic", false, "map.csv", "\n0.000000,-180.000000,-400.000000,-500.000000,-200.000000,-107.159320,91.304743,",
         "\n0.000000,-180.000000,-400.000000,-500.000000,-200.000000,-107.159320,-91.304743,", "map.csv",
         "\n0.000000,-180.000000,-400.000000,-500.000000,-200.000000,", "map.csv:27: 1039 rows do not form a full grid (1040 nodes)"},
    };
    test::ScratchDir dir("verify-damaged-all");
    const std::string m = src("samples/machines/table-table-ac.xml"), p = src("samples/plans/table-table-ac-rtest.xml"),
                      full = src("samples/deviations/table-table-ac-truth.csv"), claimed = dir.file("claimed.csv");
    test::writeText(claimed, "name,alias,value,unit\nEY0A,,-5,um\nEZ0A,,-68,um\nEX0C,,-5,um\nEY0C,,-2,um\n");
    for (const Case& c : cases) {
        const std::string truth = c.claimedTruth ? claimed : full, good = dir.file(std::string(c.backend) + "-good");
        // The identified values as they are (--copy-identified): the damaged lines' numbers are those of that header.
        auto r = test::runCli("emit --copy-identified --controller " + std::string(c.backend) + " --machine " + m +
                              " --deviations " + truth + " --out " + good);
        ASSERT_EQ(r.exitCode, 0) << r.out;
        const auto gate = [&](const std::string& folder) {
            return test::runCli("verify --machine " + m + " --plan " + p + " --truth " + truth + " --compensation " + folder +
                                " --max-residual-um 0.1");
        };
        r = gate(good);
        EXPECT_EQ(r.exitCode, 0) << c.backend << "\n" << r.out;
        // A copy of the good files with one file's text changed.
        const auto damaged = [&](const std::string& name, const std::string& file, const std::string& from, const std::string& to) {
            const std::string folder = dir.file(std::string(c.backend) + "-" + name);
            std::filesystem::copy(good, folder);
            std::string text = test::readText(folder + "/" + file);
            const size_t at = text.find(from);
            EXPECT_NE(at, std::string::npos) << c.backend << ": " << from;
            if (at != std::string::npos) text.replace(at, from.size(), to);
            test::writeText(folder + "/" + file, text);
            return gate(folder);
        };
        r = damaged("sign", c.signFile, c.signFrom, c.signTo);
        EXPECT_EQ(r.exitCode, 1) << c.backend << ": a flipped sign\n" << r.out;
        EXPECT_NE(r.out.find("above --max-residual-um"), std::string::npos) << c.backend << "\n" << r.out;
        // The whole line holding rowKey (from the line break before it to the one after it) goes.
        const std::string text = test::readText(good + "/" + c.rowFile);
        const size_t key = text.find(c.rowKey);
        ASSERT_NE(key, std::string::npos) << c.backend << ": " << c.rowKey;
        const size_t begin = c.rowKey[0] == '\n' ? key + 1 : text.rfind('\n', key) + 1, end = text.find('\n', begin) + 1;
        r = damaged("row", c.rowFile, text.substr(begin, end - begin), "");
        if (*c.rowError) {
            EXPECT_EQ(r.exitCode, 2) << c.backend << ": a missing row\n" << r.out;
            EXPECT_NE(r.out.find(c.rowError), std::string::npos) << c.backend << "\n" << r.out;
        } else {
            EXPECT_EQ(r.exitCode, 1) << c.backend << ": a missing row\n" << r.out;
        }
    }
}

TEST(Verify, CorrectedTestProgramsFolderThroughTheCli) {
    // testprog → correct (each program with its tool length, as its header says) → verify --compensation FOLDER.
    test::ScratchDir dir("verify-corrected");
    const std::string m = src("samples/machines/table-table-ac.xml"), p = src("samples/plans/table-table-ac-rtest.xml"),
                      t = src("samples/deviations/table-table-ac-truth.csv");
    auto r = test::runCli("testprog --machine " + m + " --plan " + p + " --out " + dir.file("prog"));
    ASSERT_EQ(r.exitCode, 0) << r.out;
    std::filesystem::create_directories(dir.file("corr"));
    for (const auto& e : std::filesystem::directory_iterator(dir.file("prog"))) {
        if (e.path().extension() != ".ngc") continue;
        r = test::runCli("correct --machine " + m + " --deviations " + t + " --tool-length 100 --in " + e.path().string() +
                         " --out " + dir.file("corr/" + e.path().filename().string()));
        ASSERT_EQ(r.exitCode, 0) << r.out;
    }
    r = test::runCli("verify --machine " + m + " --plan " + p + " --truth " + t + " --compensation " + dir.file("corr") +
                     " --max-residual-um 0.1");
    EXPECT_EQ(r.exitCode, 0) << r.out;
    EXPECT_NE(r.out.find("corrected test programs"), std::string::npos) << r.out;
    // Uncorrected programs do not pass the gate.
    r = test::runCli("verify --machine " + m + " --plan " + p + " --truth " + t + " --compensation " + dir.file("prog") +
                     " --max-residual-um 0.1");
    EXPECT_EQ(r.exitCode, 1) << r.out;
    // A run's program missing: refused, naming the run.
    std::filesystem::remove(dir.file("corr/TP02_YZA.ngc"));
    r = test::runCli("verify --machine " + m + " --plan " + p + " --truth " + t + " --compensation " + dir.file("corr"));
    EXPECT_EQ(r.exitCode, 2) << r.out;
    EXPECT_NE(r.out.find("YZA"), std::string::npos) << r.out;
}

TEST(Verify, EmitPrintsThePredictedResidualOfItsFiles) {
    test::ScratchDir dir("verify-emit");
    const std::string m = src("samples/machines/multitasking.xml"), p = src("samples/plans/multitasking-six-circles.xml"),
                      t = src("samples/deviations/multitasking-truth.csv");
    auto r = test::runCli("emit --controller isg --machine " + m + " --deviations " + t + " --out " + dir.file("a") + " --plan " + p);
    ASSERT_EQ(r.exitCode, 0) << r.out;
    EXPECT_NE(r.out.find("predicted residual on the identified machine"), std::string::npos) << r.out;
    // The same figure as `verify --identified` through the files.
    const auto v = test::runCli("verify --machine " + m + " --plan " + p + " --compensation " + dir.file("a") + " --identified " + t);
    ASSERT_EQ(v.exitCode, 0) << v.out;
    const auto figure = [](const std::string& out, const std::string& key) {
        const size_t at = out.find(key);
        return at == std::string::npos ? -1.0 : std::stod(out.substr(at + key.size()));
    };
    // The line of the files written (emit's candidates table above it also has a "largest span (um)" column).
    const std::string predicted = r.out.substr(r.out.find("predicted residual on the identified machine"));
    EXPECT_NEAR(figure(predicted, "largest span "), figure(v.out, "residual (largest span after compensation): "), 1e-3);
    r = test::runCli("emit --controller linuxcnc --machine " + m + " --deviations " + t + " --out " + dir.file("b"));
    ASSERT_EQ(r.exitCode, 0) << r.out;
    EXPECT_NE(r.out.find("predicted tool-tip error on the identified machine over the"), std::string::npos) << r.out;
}

TEST(Verify, NotCompensatedListReadFromAnyCommentSyntax) {
    const std::vector<controllers::OutputFile> files = {
        {"a.txt", "nothing here\n"},
        {"b.PRM", "%\n(NOT compensated:)\n(  EA0B   tilt [no parameter])\n(  EBB [constant part]  at the reference)\n(units)\n%\n"},
    };
    const auto list = app::readNotCompensated(files);
    ASSERT_EQ(list.size(), 2u);
    EXPECT_EQ(list[0].deviation, "EA0B");
    EXPECT_EQ(list[0].note, "tilt [no parameter]");
    EXPECT_EQ(list[1].deviation, "EBB [constant part]");
    EXPECT_TRUE(app::readNotCompensated({{"c.ini", "# NOT compensated:\n#   (none)\n"}}).empty());
}

TEST(Verify, EmitWarnsWhenItsFilesLeaveMoreThanNoCompensation) {
    // On the multi-tasking sample the LinuxCNC files with the identified values copied (--copy-identified; by default
    // emit writes values fitted to what the controller holds) correct the spindle and C offsets but cannot hold the
    // squareness and tilts, which partly cancelled them: the predicted ball-bar span grows (86.7 against 70.2 um). The
    // ISG files hold every deviation: no warning.
    test::ScratchDir dir("emit-worse");
    const std::string m = src("samples/machines/multitasking.xml"), p = src("samples/plans/multitasking-six-circles.xml"),
                      t = src("samples/deviations/multitasking-truth.csv");
    auto r = test::runCli("emit --controller linuxcnc-pins --copy-identified --machine " + m + " --deviations " + t + " --plan " + p +
                          " --out " + dir.file("l"));
    ASSERT_EQ(r.exitCode, 0) << r.out;
    EXPECT_NE(r.out.find("WARNING: on this machine these files leave MORE error than no compensation (ball-bar span"),
              std::string::npos)
        << r.out;
    r = test::runCli("emit --controller isg --machine " + m + " --deviations " + t + " --plan " + p + " --out " + dir.file("i"));
    ASSERT_EQ(r.exitCode, 0) << r.out;
    EXPECT_EQ(r.out.find("WARNING"), std::string::npos) << r.out;
}

TEST(Verify, TheDeviationsLeftCarryTheirIsoValueAndAliasValueAsTheDeviationFileWritesThem) {
    // Oracle: the truth CSV's text (test::deviationRowsAsWritten), not the deviation vector. The Fanuc files of the
    // multi-tasking machine cannot hold its squareness errors; verify must name them as an engineer adjusts them: the
    // ISO value under the ISO name (EC0Y −3″, EB0Z +6″, EA0C 3″), the paper's value under the alias (gXY +3″, bYZ −6″,
    // aCZ 8″), in the text, the JSON and the HTML report.
    test::ScratchDir dir("verify-left-names");
    const std::string m = src("samples/machines/multitasking.xml"), p = src("samples/plans/multitasking-six-circles.xml"),
                      t = src("samples/deviations/multitasking-truth.csv");
    auto r = test::runCli("emit --controller fanuc-30i --machine " + m + " --deviations " + t + " --out " + dir.file("f"));
    ASSERT_EQ(r.exitCode, 0) << r.out;
    r = test::runCli("verify --machine " + m + " --plan " + p + " --compensation " + dir.file("f") + " --truth " + t + " --json " +
                     dir.file("v.json") + " --report " + dir.file("r/report.html"));
    const Json v = readJsonFile(dir.file("v.json"));
    EXPECT_EQ(r.exitCode, v["passed"].boolean ? 0 : 1) << r.out;
    const auto rows = test::deviationRowsAsWritten(t);
    std::set<std::string> listed;
    for (const Json& left : v["remaining"].array) {
        if (left["iso_name"].type == Json::Type::Null) continue;
        const std::string name = left["iso_name"].string;
        listed.insert(name);
        ASSERT_TRUE(rows.count(name)) << name;
        const test::DeviationRowText& row = rows.at(name);
        EXPECT_EQ(left["unit"].string, row.unit) << name;
        EXPECT_NEAR(left["value"].num(), row.value, 1e-9) << name;
        EXPECT_EQ(left["alias"].string, row.alias) << name;
        EXPECT_NEAR(left["alias_value"].num(), row.aliasValue, 1e-9) << name;
    }
    for (const char* name : {"EC0Y", "EB0Z", "EA0C"}) EXPECT_TRUE(listed.count(name)) << name << "\n" << r.out;
    // The same numbers in the text and on the page.
    EXPECT_NE(r.out.find("  EC0Y          -3.000 arcsec  gXY +3.000 arcsec"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("  EB0Z          +6.000 arcsec  bYZ -6.000 arcsec"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("  EA0C          +3.000 arcsec  aCZ +8.000 arcsec"), std::string::npos) << r.out;
    const std::string html = test::readText(dir.file("r/report.html"));
    EXPECT_NE(html.find("<td class=\"l\">EC0Y</td><td>-3.000</td><td class=\"l\">arcsec</td><td class=\"l\">gXY</td><td>3.000</td>"),
              std::string::npos);
    EXPECT_NE(html.find("<td class=\"l\">EA0C</td><td>3.000</td><td class=\"l\">arcsec</td><td class=\"l\">aCZ</td><td>8.000</td>"),
              std::string::npos);
}

TEST(Verify, TheWorseGateAllowsATenthOfAMicronOrOnePercent) {
    // The allowance on its own (verify.hpp VerifyWorse): max(0.1 µm, 1 % of before), on the span and the tool-tip error.
    app::VerifyResult r;
    const auto worse = [&](double beforeUm, double afterUm) {
        r.residualBefore = beforeUm * kUm, r.residual = afterUm * kUm;
        return app::compensationWorse(r).span;
    };
    EXPECT_FALSE(worse(0.001, 0.001));  // noise level: equal
    EXPECT_FALSE(worse(0.001, 0.1));    // within the 0.1 µm floor
    EXPECT_TRUE(worse(0.001, 0.102));
    EXPECT_FALSE(worse(70.2, 70.8));    // within 1 % of 70.2 µm
    EXPECT_TRUE(worse(70.2, 86.3));
    EXPECT_FALSE(worse(70.2, 0.001));
    r.residualBefore = r.residual = 0;
    r.volumetric.available = true;
    r.volumetric.maxBefore = 50 * kUm, r.volumetric.maxAfter = 50.4 * kUm;
    EXPECT_FALSE(app::compensationWorse(r).any());
    r.volumetric.maxAfter = 51 * kUm;
    EXPECT_TRUE(app::compensationWorse(r).volumetric);
    r.volumetric.available = false;  // corrected programs: no volumetric figure, no volumetric verdict
    EXPECT_FALSE(app::compensationWorse(r).any());
}

TEST(Verify, ACompensationThatMakesTheMachineWorseFailsWhateverTheGate) {
    // Oracle: the simulation on the true machine. (1) A controller that copies the values of what it can hold and
    // nothing else: the ideal compensation of the deviations LinuxCNC's files take on the multi-tasking machine
    // (kLinuxCncHolds, from their "compensated:" header), at their true values; the squareness and tilts left partly
    // cancelled them, so the ball-bar span grows. (2) Every value with the wrong sign. Both exit 1 under a gate that
    // the residual alone would pass (--max-residual-um 1000), the banner first in the text, in the JSON and on the page.
    // (3) Noise-level figures do not trip it: a machine without errors, compensated by 0.001 µm.
    test::ScratchDir dir("verify-worse");
    const std::string m = src("samples/machines/multitasking.xml"), p = src("samples/plans/multitasking-six-circles.xml"),
                      t = src("samples/deviations/multitasking-truth.csv");
    const auto rows = test::deviationRowsAsWritten(t);
    // LinuxCNC's pins-and-tables route with the identified values copied holds some deviations only (its component
    // route holds all of them, and emit's fit would not write values that make the machine worse).
    auto r = test::runCli("emit --controller linuxcnc-pins --copy-identified --machine " + m + " --deviations " + t + " --out " +
                          dir.file("l"));
    ASSERT_EQ(r.exitCode, 0) << r.out;
    std::string copied = "# cnccomp-deviations/2: location errors under ISO 230-1 names are ISO values (iso_names.hpp)\nname,alias,value,unit\n", flipped = "# cnccomp-deviations/2: location errors under ISO 230-1 names are ISO values (iso_names.hpp)\nname,alias,value,unit\n";
    std::vector<std::string> held;
    for (const controllers::Coverage& c : app::readCompensated(app::readFolder(dir.file("l")))) held.push_back(c.deviation);
    ASSERT_FALSE(held.empty());
    for (const auto& [name, row] : rows) {
        if (std::find(held.begin(), held.end(), name) != held.end()) copied += fmt::format("{},,{},{}\n", name, row.value, row.unit);
        flipped += fmt::format("{},,{},{}\n", name, -row.value, row.unit);
    }
    test::writeText(dir.file("copied.csv"), copied);
    test::writeText(dir.file("flipped.csv"), flipped);
    for (const std::string name : {"copied", "flipped"}) {
        r = test::runCli("verify --machine " + m + " --plan " + p + " --compensation " + dir.file(name + ".csv") + " --truth " + t +
                         " --max-residual-um 1000 --json " + dir.file(name + ".json") + " --report " + dir.file(name + "/report.html"));
        EXPECT_EQ(r.exitCode, 1) << name << "\n" << copied << r.out;
        EXPECT_EQ(r.out.rfind("COMPENSATION MAKES THE MACHINE WORSE: largest dL span ", 0), 0u) << name << "\n" << r.out;
        EXPECT_NE(r.out.find("verification passed: residual"), std::string::npos) << r.out;  // the 1000 um gate itself holds
        EXPECT_NE(r.out.find("verification failed: COMPENSATION MAKES THE MACHINE WORSE"), std::string::npos) << r.out;
        const Json v = readJsonFile(dir.file(name + ".json"));
        EXPECT_TRUE(v["makes_machine_worse"].boolean) << name;
        EXPECT_TRUE(v["worse"]["span"].boolean) << name;
        EXPECT_FALSE(v["passed"].boolean) << name;
        EXPECT_GT(v["residual_um"].num(), v["residual_before_um"].num() + 1.0) << name;
        const std::string html = test::readText(dir.file(name + "/report.html"));
        const size_t banner = html.find("<div class=\"alarm\" role=\"alert\">COMPENSATION MAKES THE MACHINE WORSE");
        EXPECT_NE(banner, std::string::npos) << name;
        EXPECT_LT(banner, html.find("<h1>")) << name;  // above everything else on the page
    }
    // Without any gate too.
    r = test::runCli("verify --machine " + m + " --plan " + p + " --compensation " + dir.file("flipped.csv") + " --truth " + t);
    EXPECT_EQ(r.exitCode, 1) << r.out;
    // Noise level: before 0, after ≈ 0.001 µm.
    test::writeText(dir.file("zero.csv"), "name,alias,value,unit\n");
    test::writeText(dir.file("tiny.csv"), "name,alias,value,unit\nEX0C,,0.001,um\n");
    r = test::runCli("verify --machine " + m + " --plan " + p + " --compensation " + dir.file("tiny.csv") + " --truth " +
                     dir.file("zero.csv") + " --json " + dir.file("tiny.json"));
    EXPECT_EQ(r.exitCode, 0) << r.out;
    EXPECT_FALSE(readJsonFile(dir.file("tiny.json"))["makes_machine_worse"].boolean);
    EXPECT_EQ(r.out.find("WORSE"), std::string::npos) << r.out;
}

TEST(Verify, AShiftedDatumPassesTheSpanGateAndFailsTheVolumetricGate) {
    // The Heidenhain TAB's Trans X row of C on the A/C cradle moves the workpiece datum along A's axis line (see
    // ControllerHeidenhain.ATransRowThatShiftsTheDatum...): a sign flipped there is invisible to an R-test or ball bar
    // set at each run's start, so --max-residual-um passes; the volumetric figure sees the 10 um.
    test::ScratchDir dir("verify-datum");
    const std::string m = src("samples/machines/table-table-ac.xml"), p = src("samples/plans/table-table-ac-rtest.xml"),
                      t = src("samples/deviations/table-table-ac-truth.csv");
    auto r = test::runCli("emit --controller heidenhain-tnc --machine " + m + " --deviations " + t + " --out " + dir.file("f"));
    ASSERT_EQ(r.exitCode, 0) << r.out;
    std::string tabName;
    for (const auto& e : std::filesystem::directory_iterator(dir.file("f")))
        if (e.path().extension() == ".TAB") tabName = e.path().string();
    ASSERT_FALSE(tabName.empty());
    std::string tab = test::readText(tabName);
    const std::string row = "Trans     X     -0.005000000";
    ASSERT_NE(tab.find(row), std::string::npos) << tab;
    tab.replace(tab.find(row), row.size(), "Trans     X     0.005000000 ");
    test::writeText(tabName, tab);
    const std::string verify = "verify --machine " + m + " --plan " + p + " --truth " + t + " --compensation " + dir.file("f");
    r = test::runCli(verify + " --max-residual-um 0.1 --json " + dir.file("a.json"));
    EXPECT_EQ(r.exitCode, 0) << r.out;
    r = test::runCli(verify + " --max-residual-um 0.1 --max-volumetric-um 1 --json " + dir.file("b.json"));
    EXPECT_EQ(r.exitCode, 1) << r.out;
    EXPECT_NE(r.out.find("volumetric tool-tip error"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("is above --max-volumetric-um 1"), std::string::npos) << r.out;
    EXPECT_NE(test::readText(dir.file("b.json")).find("\"max_volumetric_um\": 1,\n  \"passed\": false"), std::string::npos);
    r = test::runCli(verify + " --max-volumetric-um -1");
    EXPECT_EQ(r.exitCode, 2) << r.out;
}

}  // namespace
}  // namespace cnccomp
