// The probing program of a sphere plan in four dialects (postproc/testprog/probe_program.hpp), read back.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <regex>
#include <sstream>

#include "cnccomp/error.hpp"
#include "cnccomp/identification/sphere_probe.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "cnccomp/io/probe_log.hpp"
#include "postproc/testprog/probe_program.hpp"
#include "postproc/testprog/read_back.hpp"
#include "test_support.hpp"

namespace cnccomp {
using namespace cnccomp::identification;
using namespace cnccomp::io;
using namespace cnccomp::measurement;
namespace {

const MachineModel& tableTable() { return test::sampleMachine("table-table-ac"); }
MeasurementPlan samplePlan() { return readPlanXml(test::sourcePath("samples/plans/table-table-ac-sphere.xml")); }

TEST(ProbeProgram, EveryDialectReadsBackTheCommandedTouchTargets) {
    // Round trip through cnccomp's readers: the probing blocks' end points (readProbeTargets: the post-processor's lexer
    // for the ISO dialects) and every rapid (readPoses, the post-processor's modal reader) against the commands.
    const MachineModel& m = tableTable();
    const MeasurementPlan plan = samplePlan();
    for (auto d : {postproc::Dialect::Rs274ngc, postproc::Dialect::Fanuc, postproc::Dialect::Sinumerik,
                   postproc::Dialect::Heidenhain}) {
        postproc::testprog::ProbeProgramOptions o;
        o.dialect = d;
        const postproc::testprog::ProbeProgram p = postproc::testprog::makeProbeProgram(m, plan, o);
        ASSERT_EQ(p.touches, 115);
        ASSERT_EQ(p.targets.size(), 115u);
        const std::string& text = p.files[0].text;
        const auto targets = postproc::testprog::readProbeTargets(m, text, d, p.files[0].file);
        ASSERT_EQ(targets.size(), p.targets.size()) << postproc::dialectName(d, postproc::DialectUse::Write);
        for (size_t i = 0; i < targets.size(); ++i)
            EXPECT_LT((targets[i] - p.targets[i].target).cwiseAbs().maxCoeff(), 1e-6)
                << postproc::dialectName(d, postproc::DialectUse::Write) << " touch " << i;
        // Lines < 255 characters (LinuxCNC's LINELEN), the header says the kinematics mode.
        std::istringstream in(text);
        for (std::string l; std::getline(in, l);) EXPECT_LT(l.size(), 255u) << l;
        if (d == postproc::Dialect::Heidenhain) {
            ASSERT_EQ(p.files.size(), 2u);  // the FN 16 format file
            EXPECT_NE(p.files[1].text.find("TOUCH %1.0LF"), std::string::npos);
            continue;
        }
        // Every approach point is a rapid the modal reader finds, in order.
        const auto rows = postproc::testprog::readPoses(m, text, d, p.files[0].file);
        size_t next = 0;
        for (const auto& r : rows) {
            if (next == p.targets.size()) break;
            const AxisVector& a = p.targets[next].approach;
            bool same = true;
            for (const char* ax : {"X", "Y", "Z"}) {
                const int i = m.axisIndex(ax);
                same = same && (r.known & (1u << i)) && std::abs(r.q[i] - a[i]) < 1e-6;
            }
            if (same) ++next;
        }
        EXPECT_EQ(next, p.targets.size()) << postproc::dialectName(d, postproc::DialectUse::Write);
    }
}

TEST(ProbeProgram, LinuxCncShapeIsTheContract) {
    postproc::testprog::ProbeProgramOptions o;
    o.log = "run1.txt";
    const postproc::testprog::ProbeProgram p = postproc::testprog::makeProbeProgram(tableTable(), samplePlan(), o);
    const std::string& t = p.files[0].text;
    EXPECT_EQ(p.files[0].file, "probe.ngc");
    EXPECT_NE(t.find("(LOGOPEN,run1.txt)\n"), std::string::npos);
    // The tool length (100 mm) is given with G43.1 and taken off every Z word, as the ball-bar programs do (the generated
    // kinematics component keeps the point at that length exact); the log carries the machine's Z, #5063 + L.
    EXPECT_NE(t.find("\nG43.1 Z100.000000\n"), std::string::npos);
    EXPECT_LT(t.find("G43.1"), t.find("G38.3"));
    EXPECT_NE(t.find("\nG4 P0.05\nG38.3 X100.000000 Y50.000000 Z54.500000 F100\n"
                     "#100=[#5063+100.000000]\n"
                     "(LOG,TOUCH 0 0 #5070 #5061 #5062 #100 #5064 #5065 #5066)\n"),
              std::string::npos);
    // Every probing move after the settling dwell (LinuxCNC's stale DONE, probe_program.hpp).
    size_t probes = 0, settled = 0;
    for (size_t at = t.find("G38.3"); at != std::string::npos; at = t.find("G38.3", at + 1)) {
        ++probes;
        settled += at >= 9 && t.compare(at - 9, 9, "G4 P0.05\n") == 0;
    }
    EXPECT_EQ(probes, static_cast<size_t>(p.touches));
    EXPECT_EQ(settled, probes);
    EXPECT_NE(t.find("(LOG,TOUCH 22 4 #5070 #5061 #5062 #100 #5064 #5065 #5066)"), std::string::npos);
    EXPECT_NE(t.find("G49\n(LOGCLOSE)\nM2\n"), std::string::npos);
    EXPECT_LT(t.find("(LOGOPEN"), t.find("G38.3"));
    o.log = "a,b";
    EXPECT_THROW(postproc::testprog::makeProbeProgram(tableTable(), samplePlan(), o), ModelError);
}

TEST(ProbeProgram, LinuxCncInterpreterReadsItProbesTheTargetsAndLogsLinesTheReaderReads) {
    // Oracle: LinuxCNC's own interpreter (rs274, standalone: no motion, so no probe trips). It must read the program
    // without error, make one STRAIGHT_PROBE per touch to the commanded target, and expand each (LOG,…) line; those
    // lines, read by the probe result reader, name the first touch as missed (#5070 = 0 without a probe).
    const std::string rs274 = test::rs274Path();
    if (rs274.empty()) GTEST_SKIP() << "rs274 not found: LinuxCNC's interpreter comes with the Debian package linuxcnc-uspace";
    const MachineModel& m = tableTable();
    const MeasurementPlan plan = samplePlan();
    const postproc::testprog::ProbeProgram p = postproc::testprog::makeProbeProgram(m, plan, {});
    test::ScratchDir dir("probe-rs274");
    const std::string ngc = dir.file("probe.ngc"), out = dir.file("canon.txt"), log = dir.file("rs.log"),
                      tbl = dir.file("tool.tbl");
    test::writeText(ngc, p.files[0].text);
    test::writeText(tbl, "");
    const std::string cmd = "cd '" + dir.path.string() + "' && " + test::rs274Command(dir.path.string(), tbl, ngc, out, log);
    ASSERT_EQ(std::system(cmd.c_str()), 0) << test::readText(log);
    const std::string canon = test::readText(out);
    const std::regex probe(R"(STRAIGHT_PROBE\(([-0-9.]+), ([-0-9.]+), ([-0-9.]+), ([-0-9.]+), ([-0-9.]+), ([-0-9.]+)\))");
    const std::regex logLine(R"re(LOG\("(TOUCH [^"]*)"\))re");
    // The canonical positions leave out the tool length offset (motion adds it): USE_TOOL_LENGTH_OFFSET gives it (G43.1).
    const std::regex offset(R"(USE_TOOL_LENGTH_OFFSET\([-0-9.]+ [-0-9.]+ ([-0-9.]+),)");
    double toolZ = 0;
    std::vector<std::array<double, 6>> probes;
    std::string logText;
    std::istringstream in(canon);
    for (std::string l; std::getline(in, l);) {
        std::smatch s;
        if (std::regex_search(l, s, offset)) {
            toolZ = std::stod(s[1]);
        } else if (std::regex_search(l, s, probe)) {
            std::array<double, 6> v{};
            for (int k = 0; k < 6; ++k) v[static_cast<size_t>(k)] = std::stod(s[k + 1]);
            v[2] += toolZ;
            probes.push_back(v);
        } else if (std::regex_search(l, s, logLine)) {
            logText += s[1].str() + "\n";
        }
    }
    ASSERT_EQ(probes.size(), p.targets.size());
    for (size_t i = 0; i < probes.size(); ++i)
        for (int k = 0; k < 3; ++k)  // rs274 prints four decimals
            EXPECT_NEAR(probes[i][static_cast<size_t>(k)], p.targets[i].target[m.axisIndex(std::string(1, "XYZ"[k]))], 6e-5);
    const ProbeLog pl = parseProbeLog(logText, "rs274-log", m);
    ASSERT_EQ(pl.touches.size(), 115u);
    EXPECT_EQ(pl.touches[0].triggered, 0);
    EXPECT_EQ(pl.touches[114].pose, 22);
    EXPECT_EQ(pl.touches[114].touch, 4);
    try {
        sphereObservations(m, sphereCommands(m, plan.sphereRuns), pl);
        FAIL() << "expected the missed touch";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("pose 0 touch 0: missed"), std::string::npos) << e.what();
    }
}

TEST(ProbeProgram, CliWritesTheProgramAndIdentifyReadsTheSimulatedResult) {
    // The whole chain through the command line: testprog, simulate (the result file), identify (exit 0, the eight location errors and the three squareness errors).
    test::ScratchDir dir("probe-cli");
    const std::string M = test::sourcePath("samples/machines/table-table-ac.xml");
    const std::string P = test::sourcePath("samples/plans/table-table-ac-sphere.xml");
    const std::string T = test::sourcePath("samples/deviations/table-table-ac-truth.csv");
    auto r = test::runCli("testprog --machine " + M + " --plan " + P + " --dialect heidenhain --out " + dir.file("tnc"));
    ASSERT_EQ(r.exitCode, 0) << r.out;
    EXPECT_TRUE(std::filesystem::exists(dir.file("tnc/PROBE.h")));
    EXPECT_TRUE(std::filesystem::exists(dir.file("tnc/PROBE.A")));
    r = test::runCli("simulate --machine " + M + " --plan " + P + " --deviations " + T + " --out " + dir.file("sim") +
                     " --probe-log run.txt");
    ASSERT_EQ(r.exitCode, 0) << r.out;
    r = test::runCli("identify --machine " + M + " --plan " + P + " --traces " + dir.file("sim") + " --probe-log run.txt --out " +
                     dir.file("d.csv"));
    ASSERT_EQ(r.exitCode, 0) << r.out;
    EXPECT_NE(r.out.find("identified 11 of 11"), std::string::npos) << r.out;  // 8 location errors, 3 squareness
    // No result file: exit 2 naming it.
    r = test::runCli("identify --machine " + M + " --plan " + P + " --traces " + dir.file("sim") + " --out " + dir.file("e.csv"));
    EXPECT_EQ(r.exitCode, 2) << r.out;
    EXPECT_NE(r.out.find("cnccomp-probe.txt"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace cnccomp

namespace cnccomp {
namespace {

TEST(ProbeVerify, TheCentresSpreadBeforeAndCoincideAfterAnIdealOrEmittedCompensation) {
    // verify on a sphere plan: the probing program's moves on the true machine, without and with the compensation of the
    // identified set; the fitted centres spread by the errors before and coincide after (the identified set is the
    // truth's location and squareness errors, found from the simulated result file).
    test::ScratchDir dir("probe-verify");
    const std::string M = test::sourcePath("samples/machines/table-table-ac.xml");
    const std::string P = test::sourcePath("samples/plans/table-table-ac-sphere.xml");
    const std::string T = test::sourcePath("samples/deviations/table-table-ac-truth.csv");
    auto r = test::runCli("simulate --machine " + M + " --plan " + P + " --deviations " + T + " --out " + dir.file("sim"));
    ASSERT_EQ(r.exitCode, 0) << r.out;
    r = test::runCli("identify --machine " + M + " --plan " + P + " --traces " + dir.file("sim") + " --out " + dir.file("d.csv"));
    ASSERT_EQ(r.exitCode, 0) << r.out;
    for (const std::string& controller : {std::string(""), std::string("linuxcnc"), std::string("siemens-840d")}) {
        std::string comp = dir.file("d.csv");
        if (!controller.empty()) {
            comp = dir.file("emit-" + controller);
            r = test::runCli("emit --machine " + M + " --deviations " + dir.file("d.csv") + " --controller " + controller +
                             " --out " + comp);
            ASSERT_EQ(r.exitCode, 0) << r.out;
        }
        r = test::runCli("verify --machine " + M + " --plan " + P + " --compensation " + comp + " --truth " + T +
                         " --json " + dir.file("v-" + controller + ".json"));
        ASSERT_EQ(r.exitCode, 0) << controller << "\n" << r.out;
        EXPECT_NE(r.out.find("sphere probing (centre spread)"), std::string::npos) << r.out;
        // "residual (largest span after compensation): 0.000 um (before: 128.190 um)"
        const size_t at = r.out.find("residual (largest span after compensation): ");
        ASSERT_NE(at, std::string::npos) << r.out;
        const double after = std::stod(r.out.substr(at + 44));
        const double before = std::stod(r.out.substr(r.out.find("(before: ", at) + 9));
        EXPECT_GT(before, 50.0) << controller;
        EXPECT_LT(after, 0.05) << controller << "\n" << r.out;
    }
}

}  // namespace
}  // namespace cnccomp
