// Test programs (`cnccomp testprog`): every sample plan in every dialect read back through cnccomp's own reader
// (`poses`, Klartext included) gives the commands the simulation uses; LinuxCNC's own interpreter reads the
// RS274NGC programs and its canonical moves agree; travel limits; all-or-nothing writing.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/identification/dbb5_run.hpp"
#include "cnccomp/identification/rtest_run.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "postproc/testprog/read_back.hpp"
#include "postproc/testprog/test_program.hpp"
#include "test_support.hpp"

namespace cnccomp {
using namespace cnccomp::identification;
using namespace cnccomp::io;
using namespace cnccomp::measurement;
namespace {


constexpr postproc::Dialect kDialects[] = {postproc::Dialect::Rs274ngc, postproc::Dialect::Fanuc, postproc::Dialect::Sinumerik,
                                        postproc::Dialect::Heidenhain};

struct SamplePlan {
    std::string file;
    MeasurementPlan plan;
    MachineModel machine;
};

/// Every plan in samples/plans with the machine it names.
const std::vector<SamplePlan>& samplePlans() {
    static const std::vector<SamplePlan> plans = [] {
        std::vector<SamplePlan> out;
        for (const auto& e : std::filesystem::directory_iterator(test::sourcePath("samples/plans"))) {
            SamplePlan s{e.path().filename().string(), readPlanXml(e.path().string()), MachineModel{}};
            if (!s.plan.sphereRuns.empty()) continue;  // probing programs: tests/postproc/testprog/test_probe_program.cpp
            s.machine = readMachineXml(test::sourcePath("samples/machines/" + s.plan.machine + ".xml"));
            out.push_back(std::move(s));
        }
        std::sort(out.begin(), out.end(), [](const SamplePlan& a, const SamplePlan& b) { return a.file < b.file; });
        return out;
    }();
    return plans;
}

/// Largest difference per axis kind: mm for linear axes, degrees for rotary axes.
void expectSamePose(const MachineModel& m, const AxisVector& got, const AxisVector& want, const std::string& where) {
    for (int a = 0; a < m.axisCount(); ++a) {
        const bool rotary = m.axisLink(a).kind == AxisKind::Rotary;
        const double d = std::abs(got[a] - want[a]) / (rotary ? kDeg : 1.0);
        ASSERT_LE(d, 1e-6) << where << " axis " << m.axisNames[a] << (rotary ? " (deg)" : " (mm)");
    }
}

/// The commands the simulation uses, straight from the simulation's own functions (not from RunMotion).
AxisVector simulationCommands(const MachineModel& m, const postproc::testprog::RunMotion& r, double t) {
    if (r.ballbar) return runCommands(m, *r.ballbar, t * kDeg);
    if (r.circle) return linearCircleCommands(m, *r.circle, t);
    if (r.dbb5) return dbb5Commands(m, *r.dbb5, t);
    static std::map<const RtestRun*, std::vector<AxisVector>> cache;
    auto it = cache.find(r.rtest);
    if (it == cache.end()) it = cache.emplace(r.rtest, rtestCommands(m, *r.rtest)).first;
    return it->second[static_cast<size_t>(t)];
}
AxisVector simulationSetup(const MachineModel& m, const postproc::testprog::RunMotion& r) {
    if (r.ballbar) return setupCommands(m, *r.ballbar);
    if (r.dbb5) return dbb5SetupCommands(m, *r.dbb5);
    if (r.circle) return linearCircleCentreCommands(m, *r.circle);
    return rtestCommands(m, *r.rtest).front();
}
std::vector<double> simulationSamples(const postproc::testprog::RunMotion& r) {
    if (r.ballbar) return r.ballbar->anglesDeg();
    if (r.dbb5) return r.dbb5->anglesDeg();
    if (r.circle) return r.circle->dataAnglesDeg();
    std::vector<double> t;
    for (int i = 0; i < r.rtest->sampleCount(); ++i) t.push_back(i);
    return t;
}

TEST(TestPrograms, EveryDialectReadsBackToTheSimulationsPosesForEverySamplePlan) {
    // Round trip through an independent reader path: the program text → `poses` (ISO interpreter or Klartext reader)
    // → commands, against the commands simulate / simulate-runs evaluate ([MultiTasking] Table 2, [IbarakiDBB5], [Moravek2019] / [RotaryTableModel]).
    ASSERT_GE(samplePlans().size(), 8u);
    for (const SamplePlan& sp : samplePlans()) {
        const auto motions = postproc::testprog::planMotions(sp.machine, sp.plan);
        for (postproc::Dialect d : kDialects) {
            postproc::testprog::TestProgramOptions o;
            o.dialect = d;
            const auto set = postproc::testprog::makeTestPrograms(sp.machine, sp.plan, o);
            ASSERT_EQ(set.programs.size(), motions.size());
            for (size_t i = 0; i < motions.size(); ++i) {
                const auto& r = motions[i];
                const std::string where = sp.file + " " + postproc::dialectName(d, postproc::DialectUse::Write) + " run " + r.name;
                const auto back = postproc::testprog::readTestProgram(sp.machine, r, set.programs[i].text, d, where);
                expectSamePose(sp.machine, back.setup, simulationSetup(sp.machine, r), where + " setup");
                const std::vector<double> samples = simulationSamples(r);
                ASSERT_EQ(back.passes.size(), 2u) << where;
                for (const auto& pass : back.passes) {
                    std::vector<double> t;
                    std::vector<AxisVector> q;
                    postproc::testprog::passSamples(r, pass, t, q);
                    ASSERT_EQ(t.size(), samples.size()) << where << " pass " << pass.label;
                    // Every sample of the simulation once per pass, in one direction.
                    std::vector<double> sorted = t;
                    std::sort(sorted.begin(), sorted.end());
                    std::vector<double> want = samples;
                    std::sort(want.begin(), want.end());
                    for (size_t k = 0; k < t.size(); ++k) ASSERT_NEAR(sorted[k], want[k], 1e-12) << where;
                    for (size_t k = 0; k < t.size(); ++k)
                        expectSamePose(sp.machine, q[k], simulationCommands(sp.machine, r, t[k]),
                                       where + " pass " + pass.label + " t=" + std::to_string(t[k]));
                }
                // CW then CCW for circles, forward then back otherwise.
                const std::string first = back.passes[0].label, second = back.passes[1].label;
                EXPECT_TRUE((first == "CW" && second == "CCW") || (first == "forward" && second == "reverse")) << where;
            }
        }
    }
}

TEST(TestPrograms, BallBarSweepsAreCircularBlocksCwFirstWithOvershootInsideTheTravel) {
    const SamplePlan* six = nullptr;
    for (const auto& sp : samplePlans())
        if (sp.file == "multitasking-six-circles.xml") six = &sp;
    ASSERT_TRUE(six);
    const auto set = postproc::testprog::makeTestPrograms(six->machine, six->plan, {});
    for (const auto& p : set.programs) {
        EXPECT_TRUE(p.arcs) << p.run;
        EXPECT_EQ(p.firstPass, "CW") << p.run;
        // C runs: the full 10°; B runs sweep ±180° on a ±185° axis: 5° left.
        const double expected = p.run.front() == 'B' ? 5.0 : 10.0;
        EXPECT_NEAR(p.overshootStart, expected, 1e-9) << p.run;
        EXPECT_NEAR(p.overshootEnd, expected, 1e-9) << p.run;
        // The first circular block after the capture stop is a G2 (CW), the sweep has one block per sample.
        const size_t begin = p.text.find("(CNCCOMP PASS 1 CW BEGIN)");
        ASSERT_NE(begin, std::string::npos);
        EXPECT_NE(p.text.find(" G2 ", begin), std::string::npos);
        EXPECT_NE(p.text.find("(CNCCOMP PASS 2 CCW BEGIN)"), std::string::npos);
    }
    // The tilting head's absolute runs use the whole B travel: no overshoot is possible.
    for (const auto& sp : samplePlans())
        if (sp.file == "tilting-head-b-patterns.xml")
            for (const auto& p : postproc::testprog::makeTestPrograms(sp.machine, sp.plan, {}).programs) {
                EXPECT_EQ(p.overshootStart, 0.0) << p.run;
                EXPECT_EQ(p.overshootEnd, 0.0) << p.run;
            }
}

// ---- LinuxCNC's interpreter as the oracle ------------------------------------------------------------------------

struct CanonMove {
    long line = 0;
    std::string kind;  ///< STRAIGHT_TRAVERSE, STRAIGHT_FEED, ARC_FEED
    double xyzabc[6] = {};
    int rotation = 0;
};

/// Parses rs274's canonical calls (saicanon output): positions of every traverse, feed and arc end.
std::vector<CanonMove> parseCanon(const std::string& text) {
    std::vector<CanonMove> out;
    std::istringstream in(text);
    std::string l;
    char plane = 'Z';  // normal of the active plane
    double zOffset = 0;  // the active tool length offset along Z
    const std::regex call(R"(^\s*\d+\s+N(\S+)\s+([A-Z_]+)\((.*)\))");
    while (std::getline(in, l)) {
        std::smatch m;
        if (!std::regex_search(l, m, call)) continue;
        const std::string name = m[2];
        if (name == "SELECT_PLANE") {
            const std::string a = m[3];
            plane = a.find("XZ") != std::string::npos ? 'Y' : a.find("YZ") != std::string::npos ? 'X' : 'Z';
            continue;
        }
        if (name == "USE_TOOL_LENGTH_OFFSET") {
            // The interpreter's positions exclude the tool length offset; LinuxCNC's canon adds it to every move
            // (emccanon.cc, rotate_and_offset_pos: x += canon.toolOffset.tran.x ...). Z is the third number.
            std::vector<double> v;
            std::stringstream args(std::regex_replace(m[3].str(), std::regex("[ ,]+"), ","));
            for (std::string cell; std::getline(args, cell, ',');)
                if (!cell.empty()) v.push_back(std::stod(cell));
            zOffset = v.size() >= 3 ? v[2] : 0.0;
            continue;
        }
        if (name != "STRAIGHT_TRAVERSE" && name != "STRAIGHT_FEED" && name != "ARC_FEED") continue;
        std::vector<double> v;
        std::stringstream args(m[3].str());
        for (std::string cell; std::getline(args, cell, ',');) v.push_back(std::stod(cell));
        CanonMove c;
        c.kind = name;
        if (name == "ARC_FEED") {
            if (v.size() < 9) continue;
            // ARC_FEED(first_end, second_end, first_centre, second_centre, rotation, axis_end, a, b, c)
            const int first = plane == 'Z' ? 0 : plane == 'Y' ? 2 : 1, second = plane == 'Z' ? 1 : plane == 'Y' ? 0 : 2;
            const int normal = plane == 'Z' ? 2 : plane == 'Y' ? 1 : 0;
            c.xyzabc[first] = v[0];
            c.xyzabc[second] = v[1];
            c.xyzabc[normal] = v[5];
            c.rotation = static_cast<int>(v[4]);
            for (int k = 0; k < 3; ++k) c.xyzabc[3 + k] = v[6 + k];
        } else {
            if (v.size() < 6) continue;
            for (int k = 0; k < 6; ++k) c.xyzabc[k] = v[k];
        }
        c.xyzabc[2] += zOffset;
        out.push_back(c);
    }
    return out;
}

TEST(TestPrograms, LinuxCncInterpreterReadsEveryProgramAndMakesTheSameMoves) {
    const std::string rs274 = test::rs274Path();
    if (rs274.empty()) GTEST_SKIP() << "rs274 not found: LinuxCNC's interpreter comes with the Debian package linuxcnc-uspace "
                                       "(tools/deps.sh installs it)";
    test::ScratchDir dir("testprog-rs274");
    const std::string tbl = dir.file("tool.tbl");
    test::writeText(tbl, "");
    int programs = 0;
    for (const SamplePlan& sp : samplePlans()) {
        // These two repeat run types of multitasking-six-circles (B-X, B-Y, C-axial, C-radial) with other geometry.
        if (sp.file == "lsq-multitasking-b-runs.xml" || sp.file == "lsq-multitasking-mounting.xml") continue;
        const auto set = postproc::testprog::makeTestPrograms(sp.machine, sp.plan, {});
        for (const auto& p : set.programs) {
            const std::string ngc = dir.file(p.file), out = dir.file(p.file + ".canon"), log = dir.file(p.file + ".log");
            test::writeText(ngc, p.text);
            const std::string cmd = test::rs274Command(dir.path.string(), tbl, ngc, out, log);
            const int status = std::system(cmd.c_str());
            ASSERT_EQ(status, 0) << sp.file << " " << p.file << ": rs274 failed:\n" << test::readText(log);
            const std::vector<CanonMove> canon = parseCanon(test::readText(out));
            const auto rows = postproc::testprog::readPoses(sp.machine, p.text, postproc::Dialect::Rs274ngc, p.file);
            ASSERT_EQ(canon.size(), rows.size()) << sp.file << " " << p.file;
            for (size_t i = 0; i < rows.size(); ++i) {
                const auto& r = rows[i];
                const AxisVector c = sp.machine.toController(r.q);
                for (int k = 0; k < 6; ++k) {
                    const int a = sp.machine.axisIndex(std::string(1, "XYZABC"[k]));
                    if (a < 0 || !(r.known & (1u << a))) continue;
                    const double mine = sp.machine.axisLink(a).kind == AxisKind::Rotary ? c[a] / kDeg : c[a];
                    // rs274 prints four decimals.
                    ASSERT_NEAR(canon[i].xyzabc[k], mine, 6e-5) << p.file << " line " << r.line << " axis " << "XYZABC"[k];
                }
                if (r.motion == "G2") {
                    EXPECT_EQ(canon[i].rotation, -1) << p.file << " line " << r.line;
                } else if (r.motion == "G3") {
                    EXPECT_EQ(canon[i].rotation, 1) << p.file << " line " << r.line;
                } else if (r.motion == "G0") {
                    EXPECT_EQ(canon[i].kind, "STRAIGHT_TRAVERSE") << p.file << " line " << r.line;
                }
            }
            ++programs;
        }
    }
    EXPECT_GE(programs, 35);
}

// ---- Travel limits and writing -------------------------------------------------------------------------------------

TEST(TestPrograms, ARunOutsideTheTravelNamesRunAndAxisAndWritesNothing) {
    MachineModel m = test::multitasking();
    for (auto& l : m.tool.links)
        if (l.name == "X") l.max = 300.0;  // C-X style runs need more; B-X reaches X = 100 + 360
    m.finalize();
    const MeasurementPlan plan = readPlanXml(test::sourcePath("samples/plans/multitasking-six-circles.xml"));
    try {
        postproc::testprog::makeTestPrograms(m, plan, {});
        FAIL() << "expected a travel error";
    } catch (const ModelError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("run 'B-X'"), std::string::npos) << what;
        EXPECT_NE(what.find("axis X"), std::string::npos) << what;
        EXPECT_NE(what.find("travel"), std::string::npos) << what;
    }
    // Through the CLI: exit status 2, and not one file in the output folder.
    test::ScratchDir dir("testprog-travel");
    std::string xml = test::readText(test::sourcePath("samples/machines/multitasking.xml"));
    const std::string from = "min=\"-700\" max=\"700\"";
    xml.replace(xml.find(from), from.size(), "min=\"-700\" max=\"300\"");
    test::writeText(dir.file("m.xml"), xml);
    const auto r = test::runCli("testprog --machine " + dir.file("m.xml") + " --plan " +
                                test::sourcePath("samples/plans/multitasking-six-circles.xml") + " --out " + dir.file("out"));
    EXPECT_EQ(r.exitCode, 2) << r.out;
    EXPECT_NE(r.out.find("run 'B-X'"), std::string::npos) << r.out;
    EXPECT_FALSE(std::filesystem::exists(dir.file("out")) && !std::filesystem::is_empty(dir.file("out")));
}

TEST(TestPrograms, CliWritesOneProgramPerRunAndAnIndexAllOrNothing) {
    test::ScratchDir dir("testprog-cli");
    const std::string plan = test::sourcePath("samples/plans/table-table-ac-rtest.xml");
    const std::string machine = test::sourcePath("samples/machines/table-table-ac.xml");
    auto r = test::runCli("testprog --machine " + machine + " --plan " + plan + " --dialect heidenhain --out " + dir.file("h"));
    ASSERT_EQ(r.exitCode, 0) << r.out;
    const std::string index = test::readText(dir.file("h/index.csv"));
    EXPECT_NE(index.find("1,XYC,R-test,TP01_XYC.h,72,forward"), std::string::npos) << index;
    const std::string h = test::readText(dir.file("h/TP05_XYZAC.h"));
    EXPECT_EQ(h.rfind("0 BEGIN PGM TP05_XYZAC MM", 0), 0u) << h.substr(0, 80);
    EXPECT_NE(h.find("CYCL DEF 9.1 DWELL 1\n"), std::string::npos);
    EXPECT_NE(h.find("END PGM TP05_XYZAC MM"), std::string::npos);
    // A folder standing where a program goes: refused before anything is written.
    std::filesystem::create_directories(dir.file("f/TP03_XYC_A_45.nc"));
    r = test::runCli("testprog --machine " + machine + " --plan " + plan + " --dialect fanuc --out " + dir.file("f"));
    EXPECT_EQ(r.exitCode, 2) << r.out;
    EXPECT_NE(r.out.find("not a regular file"), std::string::npos) << r.out;
    size_t files = 0;
    for (const auto& e : std::filesystem::directory_iterator(dir.file("f"))) files += e.is_regular_file();
    EXPECT_EQ(files, 0u);
    // Unknown dialect: exit 2, named.
    r = test::runCli("testprog --machine " + machine + " --plan " + plan + " --dialect okuma --out " + dir.file("o"));
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_NE(r.out.find("okuma"), std::string::npos);
}

TEST(TestPrograms, ProgramsStartAndEndInTheirDialectsFrame) {
    const SamplePlan* six = nullptr;
    for (const auto& sp : samplePlans())
        if (sp.file == "multitasking-six-circles.xml") six = &sp;
    ASSERT_TRUE(six);
    const auto motions = postproc::testprog::planMotions(six->machine, six->plan);
    const auto text = [&](postproc::Dialect d) {
        postproc::testprog::TestProgramOptions o;
        o.dialect = d;
        return postproc::testprog::makeTestProgram(six->machine, motions[3], 4, o).text;
    };
    const std::string fanuc = text(postproc::Dialect::Fanuc);
    EXPECT_EQ(fanuc.rfind("%\nO1004 (TP04_C_RADIAL)\n", 0), 0u) << fanuc.substr(0, 40);
    EXPECT_NE(fanuc.find("G10 L2 P1 X0.000000 Y0.000000 Z0.000000 B0.000000 C0.000000"), std::string::npos);
    EXPECT_EQ(fanuc.substr(fanuc.size() - 2), "%\n");
    const std::string siemens = text(postproc::Dialect::Sinumerik);
    EXPECT_NE(siemens.find("G500"), std::string::npos);
    EXPECT_NE(siemens.find("; CNCCOMP PASS 1 CW BEGIN"), std::string::npos);
    const std::string ngc = text(postproc::Dialect::Rs274ngc);
    EXPECT_NE(ngc.find("(MSG, MOUNT THE BAR"), std::string::npos);
    EXPECT_NE(ngc.find(" G2 X"), std::string::npos) << "C-radial circles: XY plane, CW first";
    EXPECT_EQ(ngc.find("G18"), std::string::npos);
    const std::string h = text(postproc::Dialect::Heidenhain);
    EXPECT_EQ(h.find(" CC X"), std::string::npos) << "C turns with the circle: straight blocks on a TNC [G]";
    EXPECT_NE(h.find(" L X+"), std::string::npos);
    // A DBB5 linear circle has no rotary axis in it: CC and C blocks, clockwise first.
    for (const auto& sp : samplePlans())
        if (sp.file == "dbb5-table-table-ac.xml") {
            postproc::testprog::TestProgramOptions o;
            o.dialect = postproc::Dialect::Heidenhain;
            const auto p = postproc::testprog::makeTestProgram(sp.machine, postproc::testprog::planMotions(sp.machine, sp.plan)[0], 1, o);
            EXPECT_TRUE(p.arcs);
            EXPECT_NE(p.text.find(" CC X+0.000000 Y+0.000000"), std::string::npos);
            EXPECT_NE(p.text.find(" DR- R0"), std::string::npos);
        }
}


// ---- Circles of the linear axes (<circle>, ISO 230-4) ----------------------------------------------------------------

namespace circle_programs {

const char* kCirclePlan = R"(<plan machine="mill-3axis">
  <circle name="xy" plane="XY" centre="10 -20 -250" radius="100" start="30" arc="360" step="2" tool-length="50" feed="1500" overshoot="5" directions="ccw cw"/>
  <circle name="yz" plane="YZ" centre="0 0 -250" radius="80" start="-20" arc="220" step="1" feed="800" overshoot="10"/>
</plan>
)";

}  // namespace circle_programs

TEST(TestPrograms, LinearCircleEveryDialectReadsBackThePlansCircleFeedAndDirection) {
    // Round trip: program text → cnccomp's reader (`poses`, Klartext reader) → commands, against the commands the circle's
    // simulation uses (linearCircleCommands); the plan's feed, overshoot and first direction are the program's.
    const MachineModel& m = test::sampleMachine("mill-3axis");
    test::ScratchDir dir("testprog-circle");
    test::writeText(dir.file("p.xml"), circle_programs::kCirclePlan);
    const MeasurementPlan plan = readPlanXml(dir.file("p.xml"));
    const auto motions = postproc::testprog::planMotions(m, plan);
    ASSERT_EQ(motions.size(), 2u);
    for (postproc::Dialect d : kDialects) {
        postproc::testprog::TestProgramOptions o;
        o.dialect = d;
        o.feed = 333;          // the plan's feed wins for circles
        o.overshootDeg = 20;   // and its overshoot
        const auto set = postproc::testprog::makeTestPrograms(m, plan, o);
        ASSERT_EQ(set.programs.size(), 2u);
        for (size_t i = 0; i < 2; ++i) {
            const postproc::testprog::TestProgram& p = set.programs[i];
            const LinearCircleRun& c = plan.circleRuns[i];
            const std::string where = std::string(postproc::dialectName(d, postproc::DialectUse::Write)) + " " + c.name;
            EXPECT_TRUE(p.arcs) << where;
            EXPECT_EQ(p.kind, postproc::testprog::RunKind::LinearCircle);
            EXPECT_EQ(p.firstPass, i == 0 ? "CCW" : "CW") << where;
            EXPECT_DOUBLE_EQ(p.overshootStart, c.capture.overshootDeg) << where;
            EXPECT_EQ(p.samples, c.dataAnglesDeg().size());
            EXPECT_NE(p.text.find(fmt::format("F{:g}", c.capture.feed)), std::string::npos) << where;
            EXPECT_EQ(p.text.find("F333"), std::string::npos) << where;
            const auto back = postproc::testprog::readTestProgram(m, motions[i], p.text, d, where);
            expectSamePose(m, back.setup, linearCircleCentreCommands(m, c), where + " setup");
            ASSERT_EQ(back.passes.size(), 2u);
            EXPECT_EQ(back.passes[0].label, i == 0 ? "CCW" : "CW") << where;
            for (const auto& pass : back.passes) {
                ASSERT_EQ(pass.t.size(), c.dataAnglesDeg().size()) << where;
                for (size_t k = 0; k < pass.t.size(); ++k)
                    expectSamePose(m, pass.q[k], linearCircleCommands(m, c, pass.t[k]),
                                   where + " " + pass.label + " t=" + std::to_string(pass.t[k]));
            }
        }
    }
}

TEST(TestPrograms, LinearCircleLinuxCncInterpreterMakesTheCircle) {
    // Oracle: LinuxCNC's own interpreter (rs274) reads the program; every arc ends on the commanded circle, turns the
    // plan's way (ARC_FEED rotation +1 = G3 = CCW), and the plane's third axis stays at the centre.
    const std::string rs274 = test::rs274Path();
    if (rs274.empty()) GTEST_SKIP() << "rs274 not found: LinuxCNC's interpreter comes with the Debian package linuxcnc-uspace";
    const MachineModel& m = test::sampleMachine("mill-3axis");
    test::ScratchDir dir("testprog-circle-rs274");
    test::writeText(dir.file("p.xml"), circle_programs::kCirclePlan);
    const MeasurementPlan plan = readPlanXml(dir.file("p.xml"));
    const auto set = postproc::testprog::makeTestPrograms(m, plan, {});
    const std::string tbl = dir.file("tool.tbl");
    test::writeText(tbl, "");
    for (size_t i = 0; i < set.programs.size(); ++i) {
        const auto& p = set.programs[i];
        const LinearCircleRun& c = plan.circleRuns[i];
        const std::string ngc = dir.file(p.file), out = dir.file(p.file + ".canon"), log = dir.file(p.file + ".log");
        test::writeText(ngc, p.text);
        const std::string cmd = test::rs274Command(dir.path.string(), tbl, ngc, out, log);
        ASSERT_EQ(std::system(cmd.c_str()), 0) << p.file << ": rs274 failed:\n" << test::readText(log);
        const std::vector<CanonMove> canon = parseCanon(test::readText(out));
        const std::array<char, 2> ax = linearPlaneAxes(c.plane);
        const int u = ax[0] - 'X', v = ax[1] - 'X', n = 3 - u - v;
        int arcs = 0, first = 0;
        for (const CanonMove& mv : canon) {
            if (mv.kind != "ARC_FEED") continue;
            ++arcs;
            const double du = mv.xyzabc[u] - c.centre[u], dv = mv.xyzabc[v] - c.centre[v];
            EXPECT_NEAR(std::hypot(du, dv), c.radius, 2e-4) << p.file << " arc " << arcs;  // rs274 prints 4 decimals
            EXPECT_NEAR(mv.xyzabc[n], c.centre[n], 1e-4) << p.file << " arc " << arcs;
            if (first == 0) first = mv.rotation;
        }
        // Both passes: data arc / step blocks each, plus the overshoot arcs.
        EXPECT_GE(arcs, static_cast<int>(2 * std::floor(c.arcDeg / c.stepDeg))) << p.file;
        EXPECT_EQ(first, c.directions().front()) << p.file;  // ARC_FEED rotation: +1 CCW (G3), −1 CW (G2)
    }
}

}  // namespace
}  // namespace cnccomp
