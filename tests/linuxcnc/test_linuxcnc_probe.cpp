// The probe loop closed on the real LinuxCNC 2.9 (Debian 12 linuxcnc-uspace + linuxcnc-uspace-dev, headless
// simulation): touch probe and calibration sphere on the A/C table-table machine (samples/machines/table-table-ac.xml).
// The oracle is the virtual sphere (tests/linuxcnc/virtual_sphere.comp, checked alone in
// test_linuxcnc_virtual_sphere.cpp): a realtime HAL component with a forward model of the ERRONEOUS machine written
// from the ISO 230-1 definitions apart from cnccomp's model (the truth below: the eight location errors of A and C),
// fed the joints the drives are at (joint.N.motor-pos-cmd) and driving motion.probe-input. The sphere is mounted off
// its nominal place (a set-up error) and the probe has a pre-travel: neither is told to cnccomp.
// The loop, every step as a user runs it:
//   1. `cnccomp testprog` writes the probing program of a <sphere> plan (G38.2 touches, LOGOPEN/LOG of #5070 and
//      #5061-#5066);
//   2. LinuxCNC runs it in AUTO (its interpreter, G38.2, trajectory planner, kinematics) on a configuration from
//      `cnccomp emit --controller linuxcnc` of the all-zero set (route 1, the generated kinematics component: the
//      machine as it is, uncompensated) and writes the log;
//   3. `cnccomp identify` reads the plan and the log and identifies the deviations;
//   4. `cnccomp emit --controller linuxcnc` writes the compensation (route 1: the component with the identified set),
//      halcompile builds it, a configuration is made from exactly those files (merged as their README.txt says);
//   5. the same program runs again, with the same virtual sphere.
// Shown (centres: the sphere centre of each pose fitted here — least squares, one radius shared by every pose, which
// takes up the probe's pre-travel and the servo-cycle quantisation — to the stylus ball centres the nominal machine
// puts at the logged touch positions): before, the centres spread by the true errors (tens of µm); after, by ≤ 1 µm;
// the identified set within 0.5 µm / 0.5″ of the truth.
// Measured (13 poses, 65 touches per run): before 82.1 um, identified (8 location errors + 3 squareness errors at 0 in
// the truth) within 0.083 um / 0.32" of the truth, 63-67 s.
// Open (2026-11-26): the probing program of `cnccomp testprog` runs under G49; at A = 0 the component then holds the
// spindle reference point exact, not the stylus ball 120 mm below it, and the A = 0 poses stay 8-9.5 um off (after:
// 9.5 um). The same loop with the program given G43.1 Z120 and its Z words minus 120 (as testprog's other LinuxCNC
// programs do) gave 0.30 um after (19 poses). Until testprog's sphere program does so this test fails.
// Skipped with the reason when LinuxCNC or halcompile (root) is not there; RESOURCE_LOCK linuxcnc, RUN_SERIAL.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <regex>

#include <fmt/format.h>

#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/kinematics.hpp"
#include "linuxcnc/linuxcnc_sim.hpp"
#include "linuxcnc/virtual_sphere.hpp"
#include "test_support.hpp"

namespace cnccomp::test {
using namespace cnccomp::io;
namespace {

namespace fs = std::filesystem;
namespace sim = linuxcnc_sim;
namespace vs = virtual_sphere;

constexpr int kServoPeriodNs = 100000;  // 0.1 ms: 0.5 um per servo cycle at the plan's 300 mm/min
constexpr double kTaskCycle = 0.01;     // LinuxCNC's probing race (test_linuxcnc_virtual_sphere.cpp, linuxcnc_sim run())

/// The truth: the location errors of A and C (ISO 230-1 names), a few tens of µm and arcsec.
vs::Truth truth() {
    return {{"EY0A", 30 * kUm},     {"EZ0A", -40 * kUm},     {"EB0A", 40 * kArcsec}, {"EC0A", -30 * kArcsec},
            {"EX0C", 25 * kUm},     {"EY0C", -35 * kUm},     {"EA0C", 35 * kArcsec}, {"EB0C", -25 * kArcsec}};
}

// The plan: a 25.4 mm sphere at (100, -40, 60) mm on the table, a 6 mm stylus ball 120 mm from the spindle reference,
// touches from 0.5 mm at 300 mm/min (the whole loop stays within CI's time), the pole and 4 ring points at 20°; A
// swept over ±90° at C = 0, C over a turn at A = 0 and at A = 60° (13 poses, 65 touches). The probe's trigger offset
// is stated as calibrated (this plan kind cannot tell it from EZ0A: samples/plans/table-table-ac-sphere.xml): the
// pre-travel plus half a servo cycle's motion (LinuxCNC records the first servo cycle in contact, on average half a
// cycle's motion, 0.25 µm, past the contact), 1.25 µm.
constexpr const char* kPlan = R"xml(<?xml version="1.0" encoding="UTF-8"?>
<plan machine="table-table-ac" description="sphere probing loop of the LinuxCNC oracle (tests/linuxcnc/test_linuxcnc_probe.cpp)">
  <sphere name="S" centre="100 -40 60" diameter="25.4" stylus-diameter="6" tool-length="120" approach="0.5" feed="300"
          clearance="5" latitude="20" ring="4" trigger-offset="0.00125" estimate-trigger="false">
    <group steps="4"><sweep axis="A" start="-90" end="90"/><hold axis="C" deg="0"/></group>
    <group steps="4"><hold axis="A" deg="0"/><sweep axis="C" start="0" end="360"/></group>
    <group steps="4"><hold axis="A" deg="60"/><sweep axis="C" start="0" end="360"/></group>
  </sphere>
</plan>
)xml";
const Vec3 kSphere(100, -40, 60);
constexpr double kToolLength = 120, kSphereRadius = 12.7, kBallRadius = 3;
const Vec3 kMounting(0.030, -0.020, 0.015);  // the sphere's set-up error, mm
constexpr double kPreTravel = 0.001;        // the probe's pre-travel, mm

/// Per pose the sphere centre (table frame) fitted to the stylus ball centres of its touches, with one radius shared by
/// every pose (Gauss-Newton on |p - c_k| - rho). Returns the centres; `rho` the radius.
std::vector<Vec3> fitCentres(const std::vector<std::vector<Vec3>>& balls, double& rho) {
    const int K = static_cast<int>(balls.size()), n = 3 * K + 1;
    std::vector<Vec3> c(K);
    for (int k = 0; k < K; ++k) {
        c[k] = Vec3::Zero();
        for (const Vec3& p : balls[k]) c[k] += p / static_cast<double>(balls[k].size());
    }
    rho = kSphereRadius + kBallRadius;
    for (int k = 0; k < K; ++k) c[k] -= rho * 0.3 * Vec3::UnitZ();  // below the touches (they lie on the upper cap)
    for (int it = 0; it < 30; ++it) {
        Eigen::MatrixXd JtJ = Eigen::MatrixXd::Zero(n, n);
        Eigen::VectorXd Jtr = Eigen::VectorXd::Zero(n);
        for (int k = 0; k < K; ++k)
            for (const Vec3& p : balls[k]) {
                const Vec3 d = p - c[k];
                const double r = d.norm() - rho;
                Eigen::VectorXd j = Eigen::VectorXd::Zero(n);
                j.segment<3>(3 * k) = -d / d.norm();
                j[n - 1] = -1;
                JtJ += j * j.transpose();
                Jtr += j * r;
            }
        const Eigen::VectorXd step = JtJ.ldlt().solve(-Jtr);
        for (int k = 0; k < K; ++k) c[k] += step.segment<3>(3 * k);
        rho += step[n - 1];
        if (step.norm() < 1e-12) break;
    }
    return c;
}

/// Largest distance of a centre from their mean, mm.
double spread(const std::vector<Vec3>& centres) {
    Vec3 mean = Vec3::Zero();
    for (const Vec3& c : centres) mean += c / static_cast<double>(centres.size());
    double s = 0;
    for (const Vec3& c : centres) s = std::max(s, (c - mean).norm());
    return s;
}

struct Probed {
    std::vector<Vec3> centres;
    std::vector<std::pair<double, double>> angles;  ///< A, C of each pose (deg)
    double radius = 0, seconds = 0;
    size_t touches = 0;
    int retries = 0;
};

/// One LinuxCNC session: the configuration of the emitted folder (component route, module installed), the virtual
/// sphere, the program in AUTO; the centres from its log.
Probed probe(const MachineModel& m, const fs::path& emitted, const std::string& kinsModule, const std::string& sphereModule,
             const fs::path& dir, const fs::path& programFile, double logToolLength) {
    vs::Setup s;
    s.toolLength = kToolLength;
    s.ballRadius = kBallRadius;
    s.sphereRadius = kSphereRadius;
    s.sphere = kSphere + kMounting;
    s.triggerTravel = kPreTravel;
    s.truth = truth();
    sim::SimOptions o;
    o.route = sim::Route::Component;
    o.module = kinsModule;
    o.servoPeriodNs = kServoPeriodNs;
    o.taskCycle = kTaskCycle;
    o.wideJointLimits = true;
    o.extraHal = [&](const std::string& coordinates) { return vs::hal(sphereModule, coordinates, s); };
    const sim::SimConfig config = sim::buildSimConfig(m, emitted, dir, {{1, 0.0}}, 0.0, o);
    fs::copy_file(programFile, config.dir / "program.ngc");
    // The log: where the program's LOGOPEN names it, relative to LinuxCNC's working folder (the configuration's).
    const std::string text = readText(programFile.string());
    std::smatch logName;
    EXPECT_TRUE(std::regex_search(text, logName, std::regex(R"(\(LOGOPEN,([^)]+)\))"))) << "the program opens a log";
    const sim::RunResult run = sim::run(config, {"mdi G90 G21 G94 G17 G40 G49 G54", "auto " + (config.dir / "program.ngc").string()},
                                        [&] { return vs::raceSuspect({config.dir / logName[1].str()}); });
    Probed p;
    p.seconds = run.seconds;
    p.retries = run.retries;
    const std::vector<vs::Touch> touches = vs::readTouches(config.dir / logName[1].str());
    p.touches = touches.size();
    const Kinematics nominal(m);
    std::vector<std::vector<Vec3>> balls;
    for (const vs::Touch& t : touches) {
        EXPECT_TRUE(t.ok) << "pose " << t.pose << " touch " << t.touch << ": the probe did not trigger";
        if (t.pose >= static_cast<int>(balls.size())) balls.resize(t.pose + 1), p.angles.resize(t.pose + 1);
        p.angles[t.pose] = {t.a, t.c};
        AxisVector q(m.axisCount());
        // Machine coordinates: the work offset is zero; a log of #5063 under G43.1 lacks the tool length.
        q[m.requireAxis("X")] = t.x, q[m.requireAxis("Y")] = t.y, q[m.requireAxis("Z")] = t.z + logToolLength;
        q[m.requireAxis("A")] = t.a * kDeg, q[m.requireAxis("C")] = t.c * kDeg;
        balls[t.pose].push_back(nominal.toolPointInWorkpiece(q, nominal.toolPoint(kToolLength)));
    }
    p.centres = fitCentres(balls, p.radius);
    return p;
}

/// Each centre's distance from their mean with the pose's angles, um (diagnostics).
std::string poseTable(const Probed& p) {
    Vec3 mean = Vec3::Zero();
    for (const Vec3& c : p.centres) mean += c / static_cast<double>(p.centres.size());
    std::string s;
    for (size_t k = 0; k < p.centres.size(); ++k)
        s += fmt::format(" A{:g}/C{:g}:{:.2f}", p.angles[k].first, p.angles[k].second, (p.centres[k] - mean).norm() / kUm);
    return s;
}

TEST(LinuxcncProbeLoop, SphereProbingIdentifiesAndCompensatesTheRotaryAxesOnTheRealLinuxcnc) {
    if (const std::string why = sim::unavailableReason(); !why.empty()) GTEST_SKIP() << why;
    if (const std::string why = sim::componentUnavailableReason(); !why.empty()) GTEST_SKIP() << why;
    const auto t0 = std::chrono::steady_clock::now();
    const std::string machineFile = sourcePath("samples/machines/table-table-ac.xml");
    const MachineModel m = readMachineXml(machineFile);
    ScratchDir dir("linuxcnc-probe-loop");
    writeText(dir.file("plan.xml"), kPlan);
    writeText(dir.file("zero.csv"), "name,alias,value,unit\n");
    writeText(dir.file("truth.csv"), vs::truthCsv(truth()));

    // 1. The probing program.
    const CliResult tp = runCli(fmt::format("testprog --machine {} --plan {} --dialect linuxcnc --out {}", machineFile,
                                            dir.file("plan.xml"), dir.file("testprog")));
    ASSERT_EQ(tp.exitCode, 0) << tp.out;
    fs::path program;
    for (const auto& e : fs::directory_iterator(dir.path / "testprog"))
        if (e.path().extension() == ".ngc") {
            EXPECT_TRUE(program.empty()) << "one program for the one run";
            program = e.path();
        }
    ASSERT_FALSE(program.empty()) << tp.out;
    const std::string text = readText(program.string());
    EXPECT_TRUE(text.find("G38.2") != std::string::npos || text.find("G38.3") != std::string::npos) << "probing moves";
    double programToolLength = 0;  // G43.1 Z<L>: the program's Z words are the machine's minus L
    if (std::smatch g; std::regex_search(text, g, std::regex(R"(G43\.1\s*Z\s*([-+0-9.]+))"))) programToolLength = std::stod(g[1].str());
    // The contract (postproc/testprog/probe_program.hpp): under G43.1 the program logs #100 = #5063 + L, the machine's
    // Z; a program that logged #5063 itself would leave L to the reader.
    const double logToolLength = text.find(" #5063 ") != std::string::npos ? programToolLength : 0.0;

    // 2. Before: the uncompensated machine (the component with every deviation 0).
    const CliResult emit0 = runCli(fmt::format("emit --controller linuxcnc --machine {} --deviations {} --out {} --date 2024-01-01",
                                               machineFile, dir.file("zero.csv"), dir.file("emitted-zero")));
    ASSERT_EQ(emit0.exitCode, 0) << emit0.out;
    const int id = getpid() % 100000;
    const std::string before = fmt::format("plb{}", id), after = fmt::format("pla{}", id), sphere = fmt::format("pls{}", id);
    double install = sim::installComp(vs::source(), "virtual_sphere", sphere, dir.path / "build-sphere");
    const sim::InstalledModule sphereModule{sphere};
    install += sim::installComponent(dir.path / "emitted-zero", before, dir.path / "build-before");
    const sim::InstalledModule beforeModule{before};
    const Probed p0 = probe(m, dir.path / "emitted-zero", before, sphere, dir.path / "sim-before", program, logToolLength);
    ASSERT_EQ(p0.touches, 13u * 5u);
    const fs::path log0 = dir.path / "sim-before" / "cnccomp-probe.txt";
    ASSERT_TRUE(fs::exists(log0)) << "the program's log (LOGOPEN,cnccomp-probe.txt)";

    // 3. Identify from the plan and the log.
    const CliResult idf = runCli(fmt::format("identify --machine {} --plan {} --traces {} --out {}", machineFile,
                                             dir.file("plan.xml"), (dir.path / "sim-before").string(), dir.file("identified.csv")));
    ASSERT_EQ(idf.exitCode, 0) << idf.out;
    const DeviationSet identified = readDeviationCsv(dir.file("identified.csv"), m);
    const DeviationSet truthSet = readDeviationCsv(dir.file("truth.csv"), m);

    // 4. The compensation, built and configured from exactly the emitted files.
    const CliResult emit1 = runCli(fmt::format("emit --controller linuxcnc --machine {} --deviations {} --out {} --date 2024-01-01",
                                               machineFile, dir.file("identified.csv"), dir.file("emitted")));
    ASSERT_EQ(emit1.exitCode, 0) << emit1.out;
    install += sim::installComponent(dir.path / "emitted", after, dir.path / "build-after");
    const sim::InstalledModule afterModule{after};

    // 5. The same program again.
    const Probed p1 = probe(m, dir.path / "emitted", after, sphere, dir.path / "sim-after", program, logToolLength);
    ASSERT_EQ(p1.touches, p0.touches);

    // Figures.
    double worstLength = 0, worstAngle = 0;
    std::string table;
    for (size_t i = 0; i < m.deviations.size(); ++i) {
        const DeviationDef& d = m.deviations[i];
        if (d.kind != DeviationKind::Location || (!identified.present[i] && !truthSet.present[i])) continue;
        const double got = identified.isoValue(static_cast<int>(i)), want = truthSet.isoValue(static_cast<int>(i));
        const double unit = d.isAngle() ? kArcsec : kUm;
        (d.isAngle() ? worstAngle : worstLength) = std::max(d.isAngle() ? worstAngle : worstLength, std::abs(got - want));
        table += fmt::format(" {} {:.3f}/{:.3f}{}", d.name, got / unit, want / unit, d.isAngle() ? "\"" : "um");
        EXPECT_NEAR(got, want, 0.5 * unit) << d.name << (identified.present[i] ? "" : " (not identified)");
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::cout << fmt::format(
        "[linuxcnc probe loop] {} touches per run, servo period {} us; centres spread (largest distance from their mean) "
        "before {:.2f} um, after {:.3f} um; fitted radius before {:.4f}, after {:.4f} mm (R + r - pre-travel = {:.4f}); "
        "identified/truth:{}; LinuxCNC runs {:.1f} + {:.1f} s ({} + {} retries), halcompile {:.1f} s, test {:.1f} s\n",
        p0.touches, kServoPeriodNs / 1000, spread(p0.centres) / kUm, spread(p1.centres) / kUm, p0.radius, p1.radius,
        kSphereRadius + kBallRadius - kPreTravel, table, p0.seconds, p1.seconds, p0.retries, p1.retries, install, seconds);
    ::testing::Test::RecordProperty("spread_before_um", std::to_string(spread(p0.centres) / kUm));
    ::testing::Test::RecordProperty("spread_after_um", std::to_string(spread(p1.centres) / kUm));
    ::testing::Test::RecordProperty("seconds", std::to_string(seconds));
    EXPECT_GT(spread(p0.centres), 20 * kUm) << "before: the true errors spread the centres";
    EXPECT_LE(spread(p1.centres), 1 * kUm)
        << "after compensation; per pose (um from the mean):" << poseTable(p1)
        << (programToolLength == 0 ? "\nThe program runs under G49 (no G43.1 Z<stylus length>): at the singular poses (A = 0) the kinematics "
                                     "component holds only the point at the tool-offset length exact (README, LinuxCNC route 1), here the "
                                     "spindle reference 120 mm above the stylus ball; testprog's LinuxCNC programs give their tool length "
                                     "with G43.1 Z<L> and write Z minus L for this reason."
                                   : "");
    EXPECT_LE(worstLength, 0.5 * kUm);
    EXPECT_LE(worstAngle, 0.5 * kArcsec);
}

}  // namespace
}  // namespace cnccomp::test
