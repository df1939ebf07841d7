// The real LinuxCNC 2.9 (Debian 12 linuxcnc-uspace + linuxcnc-uspace-dev, headless simulation) as the oracle of the
// component route of the LinuxCNC backend. Per sample machine: `cnccomp emit --controller linuxcnc` writes
// its files; the generated component is compiled and installed by `halcompile --install` under a name of its own;
// a sim configuration is built from exactly the files emit wrote (merged as README.txt says); LinuxCNC is driven over
// MDI through 24 poses in joint mode (G49: the words are the nominal machine's commands) and, after
// M68 E3 Q1 + M66 E0 L0, through the same 24 poses in tool-tip mode (G43 with three tool lengths, the words the tool
// tip in workpiece coordinates), and joint.N.pos-cmd is read back. Shown:
// - the joints the real LinuxCNC computes with the component agree with cnccomp's apply model (KinsComponentModel,
//   what verify and emit's prediction use) to 1e-6 mm / 1e-6 deg (real program vs cnccomp's own inverse);
// - the erroneous machine (the exact kinematics with the deviation set the files were made from) at LinuxCNC's
//   joints puts the tool tip within 0.1 um of the nominal tip the words ask for (no cnccomp model in that loop);
// - on the multi-tasking sample, one whole `cnccomp testprog` program (ball-bar run B-X: B from -180 to 180 deg at a
//   tool length of 360 mm, given by G43.1) runs through LinuxCNC's interpreter and trajectory planner in AUTO with joint and axis
//   commands and motion.tooloffset.z recorded every servo cycle (sampler + halsampler): over the measured passes the
//   tool tip of the erroneous machine at each cycle's joints stays within 0.5 um of the nominal machine's tool-tip
//   path (the nominal tips at the sampled axis commands); outside them (approach, rapids) within 10 um.
// Skipped with the reason when LinuxCNC or halcompile (root) is not there; RESOURCE_LOCK linuxcnc, RUN_SERIAL.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <iostream>

#include <fmt/format.h>

#include "cnccomp/inverse_kinematics.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/kinematics.hpp"
#include "controllers/linuxcnc/component_route.hpp"
#include "linuxcnc/linuxcnc_sim.hpp"
#include "test_support.hpp"

namespace cnccomp::test {
using namespace cnccomp::io;
namespace {

namespace fs = std::filesystem;
namespace sim = linuxcnc_sim;
using controllers::OutputFile;
using controllers::linuxcnc::KinsComponentModel;
using controllers::linuxcnc::KinsMode;

const std::vector<sim::Tool> kTools = {{1, 0.0}, {2, 60.0}, {3, 135.5}};
constexpr int kPoses = 24;

std::vector<OutputFile> readFolder(const fs::path& dir) {
    std::vector<OutputFile> files;
    for (const auto& e : fs::directory_iterator(dir))
        if (e.is_regular_file()) files.push_back({e.path().filename().string(), readText(e.path().string())});
    return files;
}

double unitOf(const MachineModel& m, int axis) { return m.axisLink(axis).kind == AxisKind::Rotary ? kDeg : 1.0; }

/// Poses over the middle of the travel: every axis at a different phase, linear axes within ±150 mm of the middle of
/// their travel (at most 60 % of it), rotary axes within ±150 deg (at most 60 % of their travel).
std::vector<AxisVector> poses(const MachineModel& m) {
    std::vector<AxisVector> out;
    for (int k = 0; k < kPoses; ++k) {
        AxisVector q(m.axisCount());
        for (int a = 0; a < m.axisCount(); ++a) {
            const Link& l = m.axisLink(a);
            const double mid = 0.5 * (l.min + l.max);
            const double half = std::min(0.6 * 0.5 * (l.max - l.min), l.kind == AxisKind::Rotary ? 150 * kDeg : 150.0);
            q[a] = mid + half * std::sin(1.7 * k + 0.9 * a + 0.3);
        }
        out.push_back(q);
    }
    return out;
}

std::string move(const std::string& letters, const controllers::linuxcnc::JointValues& words) {
    std::string s = "G0";
    for (size_t i = 0; i < letters.size(); ++i) s += fmt::format(" {}{:.9f}", letters[i], words[static_cast<int>(i)]);
    return s;
}

struct Figures {
    double jointMode = 0, toolTipMode = 0;        ///< LinuxCNC vs model, mm or deg
    double tipJoint = 0, tipToolTip = 0;          ///< erroneous machine's tip vs nominal, mm
    double axisJoint = 0, tipBefore = 0;          ///< rad; mm (no compensation)
    double program = 0;                           ///< whole program: tip error along the path, mm
    size_t samples = 0;
    size_t atProgramTool = 0;                     ///< samples compared at the program's tool length
    long worstCycle = 0;                          ///< sampler cycle of the largest distance from the path
    double programElsewhere = 0;                  ///< the same outside the measured passes (approach, rapids), mm
    long worstCycleElsewhere = 0;
    double install = 0, seconds = 0;
    int poses = 0;
};

Figures runComponentOracle(const std::string& machineName, const std::string& deviationName, const std::string& tag,
                           const std::string& plan) {
    Figures f;
    const std::string machineFile = sourcePath("samples/machines/" + machineName + ".xml");
    const std::string deviationFile = sourcePath("samples/deviations/" + deviationName + ".csv");
    const MachineModel m = readMachineXml(machineFile);
    const DeviationSet truth = readDeviationCsv(deviationFile, m);
    ScratchDir dir("linuxcnc-component-" + machineName);
    // --copy-identified: the component holds every deviation; this test is about the component, not emit's fit (which,
    // with the joint-mode tool-length gap, may move the values: README, LinuxCNC, known gap).
    const CliResult emit = runCli(fmt::format("emit --controller linuxcnc --copy-identified --machine {} --deviations {} --out {} --date 2024-01-01",
                                              machineFile, deviationFile, dir.file("emitted")));
    EXPECT_EQ(emit.exitCode, 0) << emit.out;
    const std::vector<OutputFile> files = readFolder(dir.path / "emitted");
    const KinsComponentModel joint(m, files, KinsMode::Joint), tipMode(m, files, KinsMode::ToolTip);
    EXPECT_NE(dynamic_cast<const KinsComponentModel*>(controllers::backend("linuxcnc").apply(m, files).get()), nullptr);

    const std::string module = fmt::format("ck{}{}", tag, getpid() % 100000);
    f.install = sim::installComponent(dir.path / "emitted", module, dir.path / "build");
    struct Uninstall {
        std::string module;
        ~Uninstall() { sim::uninstallComponent(module); }
    } uninstall{module};
    sim::SimOptions o;
    o.route = sim::Route::Component;
    o.module = module;
    o.servoPeriodNs = 1000000;  // no joint tables: no comp filter to keep short
    o.wideJointLimits = true;
    o.sampled = !plan.empty();
    const sim::SimConfig config = sim::buildSimConfig(m, dir.path / "emitted", dir.path / "sim", kTools, 0.0, o);
    const std::string letters = config.coordinates;
    EXPECT_EQ(letters, joint.coordinates());

    std::vector<std::string> job{"mdi G90 G21 G94 G17 G40 G49 G54 G64"};
    // The whole program first (joint mode, as cnccomp testprog's programs state).
    double programTool = 0;
    std::pair<long, long> passLines{0, 0};  ///< program lines of the first pass's start and the last pass's end marker
    if (!plan.empty()) {
        const CliResult tp = runCli(fmt::format("testprog --machine {} --plan {} --dialect linuxcnc --feed 20000 --approach-feed 20000 "
                                                "--overshoot 4 --out {}",
                                                machineFile, sourcePath("samples/plans/" + plan), dir.file("testprog")));
        EXPECT_EQ(tp.exitCode, 0) << tp.out;
        fs::path program;
        for (const auto& e : fs::directory_iterator(dir.path / "testprog"))
            if (e.path().extension() == ".ngc" && (program.empty() || e.path() < program)) program = e.path();
        const std::string text = readText(program.string());
        EXPECT_NE(text.find("kinematics mode: joint"), std::string::npos);
        const size_t at = text.find("cnccomp correct --tool-length ");
        EXPECT_NE(at, std::string::npos);
        programTool = std::stod(text.substr(at + 30));
        EXPECT_NE(text.find(fmt::format("G43.1 Z{:.6f}", programTool)), std::string::npos) << "the program gives its tool length";
        fs::copy_file(program, dir.path / "sim" / "program.ngc");
        // The measured passes: the lines between the capture's start stop and its end stop.
        const auto lineOf = [&](const std::string& marker) {
            const size_t at = text.find(marker);
            EXPECT_NE(at, std::string::npos) << marker;
            return static_cast<long>(std::count(text.begin(), text.begin() + static_cast<long>(std::min(at, text.size())), '\n')) + 1;
        };
        passLines = {lineOf("CNCCOMP PASS 1"), lineOf("CNCCOMP PASS 2 END")};
        job.push_back("sample " + (dir.path / "sim" / "program.ngc").string());
        job.push_back("mdi G90 G49 G54");
    }
    const std::vector<AxisVector> ps = poses(m);
    for (size_t k = 0; k < ps.size(); ++k) {
        job.push_back("mdi " + move(letters, joint.program(ps[k], 0.0)));
        job.push_back(fmt::format("record j{}", k));
    }
    job.push_back("mdi M68 E3 Q1");
    job.push_back("mdi M66 E0 L0");
    int tool = 0;
    std::vector<double> lengths;
    for (size_t k = 0; k < ps.size(); ++k) {
        const size_t t = k * kTools.size() / ps.size();
        if (kTools[t].number != tool) {
            tool = kTools[t].number;
            job.push_back(fmt::format("mdi T{} M6 G43", tool));
        }
        lengths.push_back(kTools[t].length);
        job.push_back("mdi " + move(letters, tipMode.program(ps[k], kTools[t].length)));
        job.push_back(fmt::format("record t{}", k));
    }

    const sim::RunResult run = sim::run(config, job);
    f.seconds = run.seconds;
    EXPECT_EQ(run.records.size(), 2 * ps.size());
    if (run.records.size() != 2 * ps.size()) return f;
    const Kinematics nominal(m), actual(m, truth);
    const auto drive = [&](const std::vector<double>& values) {
        AxisVector c(m.axisCount());
        for (int i = 0; i < m.axisCount(); ++i) c[i] = values[i] * unitOf(m, i);
        return m.fromController(c);
    };
    for (size_t k = 0; k < ps.size(); ++k) {
        const AxisVector& q = ps[k];
        for (int mode = 0; mode < 2; ++mode) {
            const sim::Record& r = run.records[mode * ps.size() + k];
            const double L = mode == 0 ? 0.0 : lengths[k];
            EXPECT_NEAR(r.toolOffset, L, 1e-12) << "motion.tooloffset.z, pose " << k;
            const AxisVector expected = m.toController(joint.joints(q, L));
            double d = 0;
            for (int i = 0; i < m.axisCount(); ++i) d = std::max(d, std::abs(r.posCmd[i] - expected[i] / unitOf(m, i)));
            (mode == 0 ? f.jointMode : f.toolTipMode) = std::max(mode == 0 ? f.jointMode : f.toolTipMode, d);
            const AxisVector j = drive(r.posCmd);
            const Vec3 tip = actual.toolPointInWorkpiece(j, actual.toolPoint(L));
            const double e = (tip - nominal.toolPointInWorkpiece(q, nominal.toolPoint(L))).norm();
            (mode == 0 ? f.tipJoint : f.tipToolTip) = std::max(mode == 0 ? f.tipJoint : f.tipToolTip, e);
            EXPECT_LT(e, 0.1 * kUm) << (mode == 0 ? "joint" : "tool-tip") << " mode, pose " << k << ": tip off by " << e / kUm << " um";
            if (mode == 0) {
                const ToolPose a = toolPose(actual, j, actual.toolPoint(100.0)), n = toolPose(nominal, q, nominal.toolPoint(100.0));
                f.axisJoint = std::max(f.axisJoint, std::acos(std::clamp(a.axis.dot(n.axis), -1.0, 1.0)));
                f.tipBefore = std::max(f.tipBefore, (actual.toolPointInWorkpiece(q, actual.toolPoint(L)) -
                                                     nominal.toolPointInWorkpiece(q, nominal.toolPoint(L))).norm());
            }
        }
        ++f.poses;
    }
    if (!plan.empty()) {
        EXPECT_EQ(run.overruns, 0);
        f.samples = run.samples.size();
        // The tool tip of the erroneous machine at each cycle's joints against the nominal tool-tip PATH (the polyline of
        // the nominal machine's tips at the sampled axis.L.pos-cmd of the neighbouring cycles). Not the same cycle's
        // point: the sampler shows the axis pins about two servo cycles ahead of the joints, and motion's cubic joint
        // interpolator smooths the joints so that while an axis accelerates the pairing of cycles is off along the path
        // (measured: 8 um at the rapid moves; the component at a standing pose agrees to 1e-10).
        // The component holds the tip at motion.tooloffset.z (0 before the program's G43.1 and after its G49); the
        // cycles around a change of it are left out.
        const size_t n = run.samples.size();
        std::vector<Vec3> nominalTip(n);
        for (size_t k = 0; k < n; ++k)
            nominalTip[k] = nominal.toolPointInWorkpiece(drive(run.samples[k].axis), nominal.toolPoint(run.samples[k].toolOffset));
        const auto toSegment = [](const Vec3& p, const Vec3& a, const Vec3& b) {
            const Vec3 d = b - a;
            const double t = d.squaredNorm() > 0 ? std::clamp((p - a).dot(d) / d.squaredNorm(), 0.0, 1.0) : 0.0;
            return (p - (a + t * d)).norm();
        };
        f.program = 0;
        for (size_t k = 8; k + 8 < n; ++k) {
            const double L = run.samples[k].toolOffset;
            if (run.samples[k - 8].toolOffset != L || run.samples[k + 8].toolOffset != L) continue;
            const Vec3 tip = actual.toolPointInWorkpiece(drive(run.samples[k].motor), actual.toolPoint(L));
            double d = 1e300;
            for (size_t i = k - 6; i < k + 4; ++i) d = std::min(d, toSegment(tip, nominalTip[i], nominalTip[i + 1]));
            const long line = run.samples[k].programLine;
            const bool inPasses = line > passLines.first && line < passLines.second;
            double& worst = inPasses ? f.program : f.programElsewhere;
            if (d > worst) worst = d, (inPasses ? f.worstCycle : f.worstCycleElsewhere) = run.samples[k].cycle;
            if (L == programTool) ++f.atProgramTool;
        }
    }
    std::cout << fmt::format(
        "[linuxcnc component] {:<26} {} poses x 2 modes, halcompile --install {:.1f} s, LinuxCNC run {:.1f} s; LinuxCNC vs model: "
        "joint mode {:.1e}, tool-tip mode {:.1e} (mm/deg); erroneous machine's tip: joint mode {:.4f} um (before {:.1f} um, tool "
        "axis {:.3f} arcsec), tool-tip mode {:.4f} um{}\n",
        machineName, f.poses, f.install, f.seconds, f.jointMode, f.toolTipMode, f.tipJoint / kUm, f.tipBefore / kUm,
        f.axisJoint / kArcsec, f.tipToolTip / kUm,
        plan.empty() ? std::string()
                     : fmt::format("; whole program ({} servo cycles, tool {:g} mm): tip within {:.4f} um of the nominal path "
                                               "over the measured passes (largest at cycle {}), {:.4f} um elsewhere (cycle {})",
                                               f.samples, programTool, f.program / kUm, f.worstCycle, f.programElsewhere / kUm,
                                               f.worstCycleElsewhere));
    return f;
}

void oracle(const std::string& machine, const std::string& deviations, const std::string& tag, const std::string& plan = "") {
    if (const std::string why = sim::unavailableReason(); !why.empty()) GTEST_SKIP() << why;
    if (const std::string why = sim::componentUnavailableReason(); !why.empty()) GTEST_SKIP() << why;
    const Figures f = runComponentOracle(machine, deviations, tag, plan);
    EXPECT_GE(f.poses, 20);
    // Joint commands agree with cnccomp's model to 1e-6 mm / 1e-6 deg; the tool tip on the erroneous machine is
    // within 0.1 um of nominal. (The driver reads the joints once they hold still: the arrival test on stat.position
    // can pass a servo cycle before the joint pins carry that cycle's inverse, which once looked like a 1e-3 gap.)
    EXPECT_LE(f.jointMode, 1e-6);
    EXPECT_LE(f.toolTipMode, 1e-6);
    EXPECT_LE(f.tipJoint, 0.1 * kUm);
    EXPECT_LE(f.tipToolTip, 0.1 * kUm);
    EXPECT_GT(f.tipBefore, 5 * kUm);  // the deviations matter (tilting head at tool length 0: 5.7 um)
    if (!plan.empty()) {
        EXPECT_GT(f.samples, 1000u);
        EXPECT_GT(f.atProgramTool, f.samples / 2) << "most of the program runs at its G43.1 tool length";
        // The whole program (G43.1 with its tool length, joint mode): the tip follows the nominal path to 0.5 um.
        EXPECT_LE(f.program, 0.5 * kUm) << "at sampler cycle " << f.worstCycle;
        // Outside the passes: the rapid approach (G0 at this simulation's 50 m/s limits, B through the singular pose
        // 180 deg) ends in a G1 that reverses Z at once; motion's cubic joint interpolation, which trails the axis
        // commands by about two cycles, overshoots that corner (joint Z 0.76 um past its end point while X and B still
        // arrive): measured 3.4 um there, the same with a constant pull of 2 mm/rad, so not the component's swing
        // across B = 180 (with the old constant 0.1 mm/rad, C swung +-1.8 deg). Nothing is measured during it.
        EXPECT_LE(f.programElsewhere, 10 * kUm) << "at sampler cycle " << f.worstCycleElsewhere;
        ::testing::Test::RecordProperty("whole_program_tip_error_um", std::to_string(f.program / kUm));
    }
}

TEST(LinuxcncComponentOracle, MultitaskingJointAndToolTipModesAndAWholeProgram) {
    oracle("multitasking", "multitasking-truth", "mt", "multitasking-six-circles.xml");
}
TEST(LinuxcncComponentOracle, TableTableAC) { oracle("controllers-table-table-ac", "controllers-table-table-ac", "ac"); }
TEST(LinuxcncComponentOracle, TableTableBCWithOffsets) { oracle("table-table-bc-offsets", "table-table-bc-offsets-truth", "bc"); }
TEST(LinuxcncComponentOracle, TiltingHeadB) { oracle("tilting-head-b", "tilting-head-b-truth", "hb"); }

}  // namespace
}  // namespace cnccomp::test
