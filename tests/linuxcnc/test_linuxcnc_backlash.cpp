// [JOINT_n] BACKLASH of `cnccomp emit --controller linuxcnc` (component route, cnccomp-kins.ini: BACKLASH = −B̄ per
// axis with a reversal value, no COMP_FILE) on the real LinuxCNC 2.9 (oracle: the real program, tests/linuxcnc/
// linuxcnc_sim.hpp). The deviation set holds reversal values only: BX = −4 µm, BY = −2.5 µm (the usual lost motion:
// BACKLASH > 0) and BZ = +3 µm (a slide that overshoots: BACKLASH = −0.003 mm, the negative case). The CLI writes the
// files; the sim configuration is built from exactly those files (the component compiled with halcompile, the INI and
// HAL fragments merged as README.txt says). One G-code program runs whole in AUTO: each axis forward, dwell, reverse,
// dwell, forward, dwell; then a blended (G64) sequence in which X and then Z reverse while the other axes keep moving;
// a dwell; all three reverse at once; a dwell. Every servo cycle (50 µs) is sampled: motor-pos-cmd − pos-cmd and
// pos-cmd − axis.L.pos-cmd of each joint, scaled by 1e6 in HAL (sum2; halsampler prints floats with 6 decimals).
//
// Expectation written from LinuxCNC 2.9's src/emc/motion/control.c (not from cnccomp's code): compute_screw_comp()
// without comp data sets backlash_corr = +0.5·backlash while joint->vel_cmd > 0, −0.5·backlash while < 0, and keeps it
// while vel_cmd == 0 ("not moving, use whatever was there before"); backlash_filt ramps to backlash_corr (the S-curve
// of the same function, symmetric in the sign of the step); output_to_hal() writes motor_pos_cmd = pos_cmd +
// backlash_filt + motor_offset (motor_offset 0 here). joint->backlash is the INI value as read (inijoint.cc
// loadJoint: Find(&backlash, "BACKLASH"), taskintf.cc emcJointSetBacklash, command.c EMCMOT_SET_JOINT_BACKLASH: no
// fabs, no check of the sign). Hence at rest after the ramp: motor-pos-cmd = pos-cmd + (BACKLASH/2)·s, s the sign of
// the joint's last motion (0 before its first), for a negative BACKLASH too.
// Shown, at every sample of every rest (after its first 100 cycles):
// - the real motor-pos-cmd equals that expectation to 1e-9 mm (X, Y, and Z with its negative BACKLASH);
// - cnccomp's apply models agree with the real LinuxCNC there: the component route's (KinsComponentModel, what
//   `verify` uses for these files) and the pins route's (LinuxcncModel, the same BACKLASH lines in cnccomp.ini);
// - the machine with the set's lost motion (lost_motion.hpp: slide = motor + (B̄/2)·s, s the motor's last motion)
//   is off the command by |B̄|/2 after each reversal without the files (a second LinuxCNC run of the same program, the
//   machine's INI with trivkins and no BACKLASH) and by less than 1e-6 mm with them;
// - in motion too (the blended sequence included): once a joint's direction has held for 100 cycles, motor-pos-cmd −
//   pos-cmd = (BACKLASH/2)·s to 1e-9 mm in every cycle;
// - the backlash filter reaches its target after every reversal, for the negative BACKLASH too, in the time of
//   compute_screw_comp's S-curve (2·sqrt(|BACKLASH|/a_max), a_max = 0.5·acc_limit, +2 −5 cycles: measured 41–54
//   cycles, 2–2.7 ms), and stays between the old and the new value on the way.
// Skipped with the reason when LinuxCNC or halcompile (root) is not there; RESOURCE_LOCK linuxcnc, RUN_SERIAL.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "cnccomp/lost_motion.hpp"
#include "controllers/backend.hpp"
#include "controllers/common/directional.hpp"
#include "controllers/linuxcnc/linuxcnc_apply.hpp"
#include "linuxcnc/linuxcnc_sim.hpp"
#include "test_support.hpp"

namespace cnccomp::test {
using namespace cnccomp::io;
namespace {

namespace fs = std::filesystem;
namespace sim = linuxcnc_sim;
using controllers::OutputFile;

constexpr double kScale = 1e6;  ///< HAL gain of the sampled differences (mm → nm)
constexpr int kSettle = 100;    ///< cycles of a rest left out (interpolation lag, backlash ramp)
/// The harness' INI (linuxcnc_sim.cpp baseIni, checked below): [JOINT_n] MAX_ACCELERATION, [TRAJ] DEFAULT_LINEAR_ACCELERATION.
constexpr double kJointAcceleration = 50000, kTrajAcceleration = 5000;

/// Reversal values of the set (µm) and the BACKLASH written for them (mm, −B̄).
constexpr double kB[3] = {-4.0, -2.5, 3.0};

const char* kProgram = R"((cnccomp: BACKLASH on the real LinuxCNC, each axis forward, reverse, forward, rests between)
G90 G21 G94 G17 G40 G49 G54 G61
G0 X0 Y0 Z-20
G1 X5 F6000
G4 P0.1
G1 X2
G4 P0.1
G1 X6
G4 P0.1
G1 Y5
G4 P0.1
G1 Y1
G4 P0.1
G1 Y4
G4 P0.1
G1 Z-15
G4 P0.1
G1 Z-22
G4 P0.1
(a blended sequence: X reverses in its middle while Y and Z move on, then Z while X and Y move on)
G64
G1 X10 Y8 Z-20
G1 X7 Y12 Z-18
G1 X5 Y15 Z-21
G61
G4 P0.1
(all three reverse at once)
G1 X8 Y10 Z-19
G4 P0.1
M2
)";

std::vector<OutputFile> readFolder(const fs::path& dir) {
    std::vector<OutputFile> files;
    for (const auto& e : fs::directory_iterator(dir))
        if (e.is_regular_file()) files.push_back({e.path().filename().string(), readText(e.path().string())});
    return files;
}

/// Per joint: sum2 `d<n>` = (motor-pos-cmd − pos-cmd)·1e6 and `p<n>` = (pos-cmd − axis.L.pos-cmd)·1e6, run after
/// motion-controller and before the sampler (position 3 of the servo thread).
std::string differencesHal(const std::string& coordinates) {
    const size_t n = coordinates.size();
    std::string s = fmt::format("loadrt sum2 count={}\n", 2 * n);
    for (size_t j = 0; j < n; ++j) {
        const char a = static_cast<char>(std::tolower(static_cast<unsigned char>(coordinates[j])));
        const size_t d = 2 * j, p = 2 * j + 1;
        s += fmt::format("addf sum2.{0} servo-thread 3\naddf sum2.{1} servo-thread 3\n", d, p);
        s += fmt::format("net jpos{0} joint.{0}.pos-cmd => sum2.{1}.in1 sum2.{2}.in0\n", j, d, p);
        s += fmt::format("net j{0} => sum2.{1}.in0\nnet ax{2} => sum2.{3}.in1\n", j, d, a, p);
        s += fmt::format("setp sum2.{0}.gain0 {2:g}\nsetp sum2.{0}.gain1 {3:g}\nsetp sum2.{1}.gain0 {2:g}\nsetp sum2.{1}.gain1 {3:g}\n", d, p,
                         kScale, -kScale);
        s += fmt::format("net backlash-d{0} sum2.{1}.out\nnet backlash-p{0} sum2.{2}.out\n", j, d, p);
    }
    return s;
}

std::vector<std::string> differenceSignals(size_t joints) {
    std::vector<std::string> s;
    for (size_t j = 0; j < joints; ++j) s.push_back(fmt::format("backlash-d{}", j));
    for (size_t j = 0; j < joints; ++j) s.push_back(fmt::format("backlash-p{}", j));
    return s;
}

/// One run's samples as the test reads them: the command (axis.L.pos-cmd as printed), motor − pos-cmd and
/// pos-cmd − command (mm, from the scaled columns).
struct Trace {
    std::vector<AxisVector> command, motorMinusJoint, jointMinusCommand;
    std::vector<AxisVector> direction;  ///< per cycle the sign of each command's last change (0 before its first)
};

Trace traceOf(const sim::RunResult& r, int joints) {
    Trace t;
    for (const sim::Sample& s : r.samples) {
        AxisVector c(joints), d(joints), p(joints);
        for (int j = 0; j < joints; ++j) {
            c[j] = s.axis[static_cast<size_t>(j)];
            d[j] = s.extra[static_cast<size_t>(j)] / kScale;
            p[j] = s.extra[static_cast<size_t>(joints + j)] / kScale;
        }
        t.command.push_back(c);
        t.motorMinusJoint.push_back(d);
        t.jointMinusCommand.push_back(p);
        AxisVector dir = t.direction.empty() ? AxisVector(AxisVector::Zero(joints)) : t.direction.back();
        if (t.command.size() > 1)
            for (int j = 0; j < joints; ++j) {
                const double d = c[j] - t.command[t.command.size() - 2][j];
                if (d != 0) dir[j] = d > 0 ? 1 : -1;
            }
        t.direction.push_back(dir);
    }
    return t;
}

/// A rest: cycles [begin, end) in which no axis command changes.
struct Rest {
    size_t begin = 0, end = 0;
};

std::vector<Rest> restsOf(const Trace& t, size_t minimum) {
    std::vector<Rest> out;
    size_t start = 0;
    for (size_t k = 1; k <= t.command.size(); ++k) {
        if (k < t.command.size() && t.command[k] == t.command[k - 1]) continue;
        if (k - start >= minimum) out.push_back({start, k});
        start = k;
    }
    return out;
}

/// s per joint at cycle k: the sign of the command's last change up to k (0 before its first): control.c's vel_cmd
/// test with the value held at rest, read from the commands.
AxisVector lastMotion(const Trace& t, size_t k) { return t.direction[k]; }

TEST(LinuxcncBacklash, TheEmittedBacklashActsAsControlCSaysNegativeIncludedAndTakesTheLostMotionOut) {
    if (const std::string why = sim::unavailableReason(); !why.empty()) GTEST_SKIP() << why;
    if (const std::string why = sim::componentUnavailableReason(); !why.empty()) GTEST_SKIP() << why;
    const ScratchDir dir("linuxcnc-backlash");
    const std::string machineFile = sourcePath("samples/machines/mill-3axis.xml");
    const MachineModel m = readMachineXml(machineFile);
    writeText(dir.file("set.csv"), fmt::format("name,alias,value,unit,alias_value\nBX,,{},um,\nBY,,{},um,\nBZ,,{},um,\n", kB[0], kB[1], kB[2]));
    const DeviationSet set = readDeviationCsv(dir.file("set.csv"), m);
    const CliResult emit = runCli(fmt::format("emit --controller linuxcnc --machine {} --deviations {} --out {} --date 2026-11-26",
                                              machineFile, dir.file("set.csv"), dir.file("emitted")));
    ASSERT_EQ(emit.exitCode, 0) << emit.out;
    const std::vector<OutputFile> files = readFolder(dir.path / "emitted");
    const std::string kinsIni = readText(dir.file("emitted/cnccomp-kins.ini"));
    for (int a = 0; a < 3; ++a)  // BACKLASH = −B̄ in mm, as written (no COMP_FILE on this route)
        EXPECT_NE(kinsIni.find(fmt::format("[JOINT_{}]\n", a)), std::string::npos) << kinsIni;
    EXPECT_NE(kinsIni.find("BACKLASH = 0.004000\n"), std::string::npos) << kinsIni;
    EXPECT_NE(kinsIni.find("BACKLASH = 0.002500\n"), std::string::npos) << kinsIni;
    EXPECT_NE(kinsIni.find("BACKLASH = -0.003000\n"), std::string::npos) << kinsIni;
    EXPECT_EQ(kinsIni.find("COMP_FILE"), std::string::npos) << kinsIni;
    EXPECT_EQ(kinsIni.find("untested"), std::string::npos) << "the [G] of the negative BACKLASH is settled:\n" << kinsIni;
    EXPECT_NE(kinsIni.find("applies it with its sign"), std::string::npos) << "the note beside Z's negative BACKLASH\n" << kinsIni;

    // cnccomp's apply models of the files: the component route's (what verify takes for this folder) and the pins route's.
    const std::unique_ptr<controllers::AppliedCompensation> applied = controllers::backend("linuxcnc").apply(m, files);
    const auto* componentModel = dynamic_cast<const controllers::common::DirectionalCompensation*>(applied.get());
    ASSERT_NE(componentModel, nullptr);
    const controllers::linuxcnc::LinuxcncModel pinsModel(m, files);

    const std::string module = fmt::format("ckbl{}", getpid() % 100000);
    const double install = sim::installComponent(dir.path / "emitted", module, dir.path / "build");
    const sim::InstalledModule installed(module);
    sim::SimOptions o;
    o.route = sim::Route::Component;
    o.module = module;
    o.servoPeriodNs = 50000;  // the backlash filter's residual bound 0.5·a·dt² (linuxcnc_sim.hpp)
    o.wideJointLimits = true;
    o.sampled = true;
    o.extraHal = differencesHal;
    o.sampledSignals = differenceSignals(3);
    // A run is 35000-40000 cycles on an idle machine; on a loaded one (a build beside it) the sampler filled its 20000
    // and lost samples, and the run took up to 130000 cycles (the dwells and the driver's waits are wall time):
    // 200000 (16 columns of 8 bytes, 26 MB of shared memory) holds a whole run.
    o.samplerDepth = 200000;
    const sim::SimConfig with = sim::buildSimConfig(m, dir.path / "emitted", dir.path / "sim-with", {}, 0.0, o);
    ASSERT_EQ(with.coordinates, "XYZ");
    const std::string simIni = readText(with.ini.string());
    EXPECT_NE(simIni.find(fmt::format("\nMAX_ACCELERATION = {:g}\nBACKLASH", kJointAcceleration)), std::string::npos) << simIni;
    EXPECT_NE(simIni.find(fmt::format("\nDEFAULT_LINEAR_ACCELERATION = {:g}\n", kTrajAcceleration)), std::string::npos) << simIni;
    // Without the files: the machine's own INI (trivkins, no BACKLASH), the same program and sampling.
    fs::create_directories(dir.path / "without");
    writeText(dir.file("without/cnccomp.ini"), "[KINS]\nKINEMATICS = trivkins coordinates=XYZ\nJOINTS = 3\n");
    writeText(dir.file("without/cnccomp.hal"), "# nothing\n");
    sim::SimOptions w = o;
    w.route = sim::Route::Pins;
    w.module.clear();
    w.switchkins = false;  // trivkins has no motion.switchkins-type
    const sim::SimConfig without = sim::buildSimConfig(m, dir.path / "without", dir.path / "sim-without", {}, 0.0, w);
    for (const sim::SimConfig* c : {&with, &without}) writeText((c->dir / "program.ngc").string(), kProgram);

    const sim::RunResult runWith = sim::run(with, {"sample " + (with.dir / "program.ngc").string()});
    const sim::RunResult runWithout = sim::run(without, {"sample " + (without.dir / "program.ngc").string()});
    EXPECT_EQ(runWith.overruns, 0);
    EXPECT_EQ(runWithout.overruns, 0);
    const Trace tw = traceOf(runWith, 3), to = traceOf(runWithout, 3);
    const std::vector<Rest> rests = restsOf(tw, 300), restsWithout = restsOf(to, 300);
    // The start (before the program) and the 10 dwells (the last running into the end); on a loaded machine a stop
    // between two moves can last 300 cycles too (a further rest, checked the same way).
    ASSERT_GE(rests.size(), 11u) << runWith.samples.size() << " samples";
    ASSERT_GE(restsWithout.size(), 11u) << runWithout.samples.size() << " samples";

    double worstExpect = 0, worstComponent = 0, worstPins = 0, worstWith = 0, worstJoint = 0;
    double worstWithoutDiff = 0, smallestWithout = 1e300;
    size_t checked = 0, reversalRests = 0;
    std::array<int, 3> negativeSeen{};
    // Without the files: the motor is the command, the slide off by (B̄/2)·s.
    for (const Rest& restO : restsWithout)
        for (size_t k = restO.begin + kSettle; k < restO.end; ++k) {
            const AxisVector& q = to.command[k];
            const AxisVector s = lastMotion(to, k);
            const AxisVector offset = to.motorMinusJoint[k] + to.jointMinusCommand[k];
            EXPECT_EQ(offset.cwiseAbs().maxCoeff(), 0.0) << "without the files the motor is the command";
            const AxisVector err = m.toController(withLostMotion(set, m.fromController(q + offset), s)) - q;
            for (int j = 0; j < 3; ++j) {
                if (s[j] == 0) continue;
                worstWithoutDiff = std::max(worstWithoutDiff, std::abs(std::abs(err[j]) - 0.5 * std::abs(kB[j]) * kUm));
                smallestWithout = std::min(smallestWithout, std::abs(err[j]));
            }
        }
    for (size_t r = 0; r < rests.size(); ++r) {
        const Rest& rest = rests[r];
        for (size_t k = rest.begin + kSettle; k < rest.end; ++k) {
            const AxisVector& q = tw.command[k];
            const AxisVector s = lastMotion(tw, k);
            const AxisVector offset = tw.motorMinusJoint[k] + tw.jointMinusCommand[k];  // motor-pos-cmd − command
            for (int j = 0; j < 3; ++j) {
                worstJoint = std::max(worstJoint, std::abs(tw.jointMinusCommand[k][j]));  // the component at zero deviations
                // control.c: motor_pos_cmd − pos_cmd = backlash_filt = backlash_corr = (BACKLASH/2)·s at rest.
                const double backlash = -kB[j] * kUm;
                const double e = tw.motorMinusJoint[k][j] - 0.5 * backlash * s[j];
                worstExpect = std::max(worstExpect, std::abs(e));
                EXPECT_NEAR(e, 0.0, 1e-9) << "joint " << j << " at cycle " << runWith.samples[k].cycle << " (s " << s[j] << ")";
                if (backlash < 0 && s[j] != 0) ++negativeSeen[static_cast<size_t>(j)];
            }
            // cnccomp's models (description frame = controller frame here: no machine zero) at the same command and directions.
            const AxisVector qd = m.fromController(q);
            const AxisVector component = m.toController(componentModel->driveCommandsMoving(qd, 0.0, s)) - q;
            const AxisVector pins = m.toController(pinsModel.driveCommandsMoving(qd, 0.0, s)) - q;
            worstComponent = std::max(worstComponent, (component - offset).cwiseAbs().maxCoeff());
            worstPins = std::max(worstPins, (pins - offset).cwiseAbs().maxCoeff());
            // The machine with the set's lost motion: slide = motor + (B̄/2)·s_motor (lost_motion.hpp), s_motor the motor's
            // last motion = the command's (the filter moves the motor the new way at a reversal).
            const AxisVector slideWith = withLostMotion(set, m.fromController(q + offset), s);
            worstWith = std::max(worstWith, (m.toController(slideWith) - q).cwiseAbs().maxCoeff());
            ++checked;
        }
        if (r > 0) {
            const AxisVector before = lastMotion(tw, rests[r - 1].end - 1), now = lastMotion(tw, rest.end - 1);
            for (int j = 0; j < 3; ++j)
                if (before[j] != 0 && now[j] != before[j]) ++reversalRests;
        }
    }
    EXPECT_GT(checked, 3000u);
    EXPECT_GE(reversalRests, 8u);  // X ×2, Y ×2, Z, then X and Z in the blend, all three at the end
    EXPECT_GT(negativeSeen[2], 0) << "Z (negative BACKLASH) has moved";
    EXPECT_LE(worstExpect, 1e-9);
    EXPECT_LE(worstComponent, 1e-9);
    EXPECT_LE(worstPins, 1e-9);
    EXPECT_LE(worstJoint, 1e-9);
    EXPECT_LE(worstWith, 1e-6);
    EXPECT_LE(worstWithoutDiff, 1e-9);

    // In motion too (the blended sequence included): once a joint's direction has held for kSettle cycles, motor-pos-cmd −
    // pos-cmd = (BACKLASH/2)·s in every cycle (both joint pins of the same cycle: no interpolation lag in the difference).
    double worstMoving = 0;
    size_t moving = 0;
    for (size_t k = kSettle; k < tw.command.size(); ++k)
        for (int j = 0; j < 3; ++j) {
            const double sj = tw.direction[k][j];
            if (sj == 0 || tw.direction[k - kSettle][j] != sj || tw.command[k][j] == tw.command[k - 1][j]) continue;
            bool held = true;
            for (size_t i = k - kSettle; i < k && held; ++i) held = tw.direction[i][j] == sj;
            if (!held) continue;
            const double e = tw.motorMinusJoint[k][j] - 0.5 * -kB[j] * kUm * sj;
            worstMoving = std::max(worstMoving, std::abs(e));
            ++moving;
        }
    EXPECT_GT(moving, 1000u);
    EXPECT_LE(worstMoving, 1e-9);

    // The ramp (compute_screw_comp's S-curve of backlash_filt): after each reversal the filter leaves the old value and
    // reaches the new one within kSettle cycles, never outside the two (negative BACKLASH included).
    int longestRamp = 0, ramps = 0;
    double rampModel = 0;  ///< largest |measured − S-curve| in cycles
    std::string rampList;  ///< joint letter and cycles from the axis pin's reversal to the filter's target
    double outside = 0;
    for (int j = 0; j < 3; ++j) {
        const double half = 0.5 * -kB[j] * kUm;
        for (size_t k = 2; k + kSettle < tw.command.size(); ++k) {
            const double d1 = tw.command[k][j] - tw.command[k - 1][j];
            if (d1 == 0) continue;
            const double sPrev = lastMotion(tw, k - 1)[j], sNew = d1 > 0 ? 1 : -1;
            if (sPrev == 0 || sPrev == sNew) continue;
            // The joint follows its axis pin a few cycles late: the filter's run is looked for from k on.
            const double from = half * sPrev, to = half * sNew;
            int n = -1;
            for (size_t i = k; i < k + kSettle; ++i) {
                const double f = tw.motorMinusJoint[i][j];
                outside = std::max(outside, std::max(f - std::max(from, to), std::min(from, to) - f));
                if (std::abs(f - to) < 2e-12) {  // the column's resolution: 1e-12 mm
                    n = static_cast<int>(i - k);
                    break;
                }
            }
            EXPECT_GE(n, 0) << "joint " << j << ": the filter did not reach " << to << " within " << kSettle << " cycles of cycle "
                            << runWith.samples[k].cycle;
            // The S-curve of compute_screw_comp from rest: accelerate at a_max = 0.5·acc_limit, decelerate at a_max (v_max
            // 0.5·MAX_VELOCITY is never reached for µm): |Δ| = 2 BACKLASH/2 in 2·sqrt(|Δ|/a_max). acc_limit is the joint's
            // MAX_ACCELERATION capped at the trajectory's acceleration (control.c get_pos_cmds, free mode, which homing
            // passes through: joint->acc_limit = emcmotStatus->acc = [TRAJ] DEFAULT_LINEAR_ACCELERATION, initraj.cc).
            // The count starts at the axis pin's reversal, which the joint follows a cycle or two later.
            const double aMax = 0.5 * std::min(kJointAcceleration, kTrajAcceleration);
            const double cycles = 2.0 * std::sqrt(std::abs(to - from) / aMax) / (o.servoPeriodNs * 1e-9);
            EXPECT_GE(n, cycles - 2) << "joint " << j << " at cycle " << runWith.samples[k].cycle;
            EXPECT_LE(n, cycles + 5) << "joint " << j << " at cycle " << runWith.samples[k].cycle;
            rampModel = std::max(rampModel, std::abs(n - cycles));
            longestRamp = std::max(longestRamp, n);
            rampList += fmt::format(" {}{}", "XYZ"[j], n);
            ++ramps;
        }
    }
    EXPECT_GE(ramps, 8);
    EXPECT_LE(outside, 2e-12);

    std::cout << fmt::format(
        "[ figures  ] real LinuxCNC 2.9, BACKLASH X {:.4f} Y {:.4f} Z {:.4f} mm (emit, component route), {} + {} servo cycles of "
        "50 us, runs {:.1f} s + {:.1f} s, halcompile {:.1f} s; {} samples at rest in {} rests ({} after reversals): "
        "|motor-pos-cmd - (pos-cmd + BACKLASH/2 s)| max {:.1e} mm; component model vs real {:.1e} mm, pins model vs real {:.1e} mm; "
        "pos-cmd - command {:.1e} mm; in motion (direction held {} cycles) {} joint samples, max {:.1e} mm; lost-motion machine: with the files max {:.1e} mm, without min {:.4f} um (|B|/2 to {:.1e} "
        "mm); {} ramps, longest {} cycles ({}), S-curve of control.c within {:.1f} cycles, overshoot {:.1e} mm\n",
        -kB[0] / 1000, -kB[1] / 1000, -kB[2] / 1000, runWith.samples.size(), runWithout.samples.size(), runWith.seconds,
        runWithout.seconds, install, checked, rests.size(), reversalRests, worstExpect, worstComponent, worstPins, worstJoint,
        kSettle, moving, worstMoving, worstWith, smallestWithout / kUm, worstWithoutDiff, ramps, longestRamp, rampList, rampModel, outside);
}

}  // namespace
}  // namespace cnccomp::test
