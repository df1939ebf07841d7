// The real LinuxCNC 2.9 (Debian 12 linuxcnc-uspace, headless simulation) as the oracle of the LinuxCNC backend.
// Per machine: `cnccomp emit --controller linuxcnc` writes its files; a sim configuration is built from exactly those
// files, merged as their README.txt says (linuxcnc_sim.hpp); LinuxCNC is driven over MDI through ≥ 20 poses (C beyond
// ±360° and negative, both approach directions, three tool lengths under G43, the G54 of cnccomp-g54.ngc) and
// joint.N.pos-cmd / joint.N.motor-pos-cmd are read back. Shown:
// - the real LinuxCNC agrees with cnccomp's apply model (LinuxcncModel, what `verify` and the backend tests use) to
//   1e-4 mm / 1e-4 deg (real program vs transcription: an independent oracle);
// - the erroneous machine (the exact kinematics with the deviations the backend claims) driven to LinuxCNC's motor
//   positions puts the tool tip within 0.1 µm of the nominal tip the program asked for (the exact model vs the real
//   controller's numbers: no cnccomp frame conversion in the loop);
// - BACKLASH in the machine's INI is not applied to joints with a COMP_FILE (the model ignores it and agrees).
// Skipped with the reason when LinuxCNC is not installed; the ctest entries share RESOURCE_LOCK linuxcnc.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <iostream>

#include <fmt/format.h>

#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/kinematics.hpp"
#include "controllers/common/files.hpp"
#include "controllers/linuxcnc/linuxcnc_apply.hpp"
#include "controllers/linuxcnc/linuxcnc_plan.hpp"
#include "linuxcnc/linuxcnc_sim.hpp"
#include "test_support.hpp"

namespace cnccomp::test {
using namespace cnccomp::io;
namespace {

namespace fs = std::filesystem;
namespace sim = linuxcnc_sim;
using controllers::OutputFile;
using controllers::linuxcnc::JointValues;
using controllers::linuxcnc::LinuxcncModel;

const std::vector<sim::Tool> kTools = {{1, 0.0}, {2, 60.0}, {3, 135.5}};
constexpr double kBacklash = 0.02;  // BACKLASH of every joint in the machine's own INI (mm / deg)

struct Pose {
    AxisVector q;     ///< nominal machine commands (description frame)
    Vec3 tip;         ///< nominal tool tip in the workpiece frame (what the program asks for)
    int tool = 1;
    double length = 0;
    int dir = 1;      ///< every joint arrives moving in this direction
};

/// Poses over the table: tip targets within 141 mm of the C axis, 20..80 mm above the workpiece origin, C from
/// -1500° to 1444.4° (beyond ±360°, negative), the tilt axis from -80° to 95°, each (tool, direction) pair.
/// The commands come from the nominal kinematics (trt: the slides move along X Y Z, so two linear steps solve it).
std::vector<Pose> poses(const MachineModel& m, const std::string& tiltAxis) {
    static const double c[] = {-1500, -1085.5, -725.25, -600, -361, -200.75, -90.5, -45, -12, 0, 15,
                               33.3, 120, 180, 270.5, 359, 361.5, 540, 725, 800, 1010.25, 1444.4};
    static const double tilt[] = {-80, -35, 0, 25, 60, 95};
    const Kinematics nominal(m);
    const int ax = m.requireAxis("X"), ay = m.requireAxis("Y"), az = m.requireAxis("Z");
    std::vector<Pose> out;
    for (int k = 0; k < static_cast<int>(std::size(c)); ++k) {
        Pose p;
        p.dir = k % 2 == 0 ? 1 : -1;
        const size_t t = k * kTools.size() / std::size(c);  // one tool change per third of the poses
        p.tool = kTools[t].number;
        p.length = kTools[t].length;
        p.tip = Vec3(100 * std::sin(1.3 * k), 100 * std::cos(0.7 * k + 0.5), 50 + 30 * std::sin(2.1 * k));
        p.q = AxisVector::Zero(m.axisCount());
        p.q[m.requireAxis("C")] = c[k] * kDeg;
        p.q[m.requireAxis(tiltAxis)] = tilt[k % std::size(tilt)] * kDeg;
        for (int it = 0; it < 3; ++it) {
            const Vec3 e = nominal.baseToWorkpiece(p.q).linear() *
                           (p.tip - nominal.toolPointInWorkpiece(p.q, nominal.toolPoint(p.length)));
            p.q[ax] += e.x();
            p.q[ay] += e.y();
            p.q[az] += e.z();
        }
        nominal.checkTravel(p.q);
        out.push_back(p);
    }
    return out;
}

std::vector<OutputFile> readFolder(const fs::path& dir) {
    std::vector<OutputFile> files;
    for (const auto& e : fs::directory_iterator(dir)) files.push_back({e.path().filename().string(), readText(e.path().string())});
    return files;
}

/// An MDI block moving to program words (joint order of the coordinates).
std::string move(const std::string& letters, const JointValues& words) {
    std::string s = "G0";
    for (size_t i = 0; i < letters.size(); ++i) s += fmt::format(" {}{:.9f}", letters[i], words[static_cast<int>(i)]);
    return s;
}

struct Figures {
    double kinematics = 0, motor = 0, tip = 0, tipBefore = 0, tipFull = 0, seconds = 0;
    double g54 = 0, jointMode = 0, jointModeMotor = 0;  ///< G54 after the program; joint mode: pos-cmd vs words, motor vs model
    int poses = 0, settled = 0;
};

Figures runOracle(const std::string& machineName, const std::string& deviationName, const std::string& tiltAxis) {
    Figures f;
    const std::string machineFile = sourcePath("samples/machines/" + machineName + ".xml");
    const std::string deviationFile = sourcePath("samples/deviations/" + deviationName + ".csv");
    const MachineModel m = readMachineXml(machineFile);
    const DeviationSet truth = readDeviationCsv(deviationFile, m);
    ScratchDir dir("linuxcnc-oracle-" + machineName);

    // 1. The files exactly as the CLI writes them.
    const CliResult emit = runCli(fmt::format("emit --controller linuxcnc-pins --copy-identified --machine {} --deviations {} --out {} --date 2024-01-01",
                                              machineFile, deviationFile, dir.file("emitted")));
    EXPECT_EQ(emit.exitCode, 0) << emit.out;
    const std::vector<OutputFile> files = readFolder(dir.path / "emitted");
    const LinuxcncModel model(m, files, controllers::linuxcnc::KinsMode::ToolTip);
    EXPECT_NE(dynamic_cast<const LinuxcncModel*>(controllers::backend("linuxcnc-pins").apply(m, files).get()), nullptr);

    // The deviations the backend claims (its coverage list).
    DeviationSet claimed = truth;
    // (In tool-tip mode, where these poses run, the trt pins and the G54 act too: "tool-tip mode only" entries.)
    for (const auto& c : controllers::backend("linuxcnc-pins").emit({m, truth, deviationName + ".csv", "2024-01-01"}).notCompensated) {
        if (c.note.starts_with(controllers::linuxcnc::kToolTipModeOnly)) continue;
        const int i = m.deviationIndex(c.deviation);
        claimed.values.segment(m.deviations[i].offset, m.deviations[i].size()).setZero();
        claimed.present[i] = 0;
    }
    const Kinematics actual(m, claimed), full(m, truth);

    // 2. The job: work offset, then per pose a tool change when needed and three moves so that every joint arrives
    // moving in the pose's direction (rotaries first, then the linear joints by exactly 1 mm with the rotaries fixed).
    const sim::SimConfig config = sim::buildSimConfig(m, dir.path / "emitted", dir.path / "sim", kTools, kBacklash);
    const std::string letters = model.coordinates();
    std::vector<std::string> job{"mdi G90 G21 G94 G17 G40 G49 G54"};
    // The emitted G54 program itself, whole, in AUTO (a comment line over LinuxCNC's 254 characters aborted
    // it with "Command too long" and G54 stayed 0).
    fs::copy_file(dir.path / "emitted" / "cnccomp-g54.ngc", config.dir / "cnccomp-g54.ngc");
    job.push_back("auto " + (config.dir / "cnccomp-g54.ngc").string());
    job.push_back("record g54");
    const std::vector<Pose> ps = poses(m, tiltAxis);
    // From the home position (far from the table on some machines) to above the table centre before any rotary
    // axis turns: a world-straight move that turns C keeps the joints within reach only near the C axis.
    job.push_back("mdi G0 X0 Y0 Z100");
    int tool = 0;
    std::vector<JointValues> expectedJoints, programs;
    for (size_t k = 0; k < ps.size(); ++k) {
        const Pose& p = ps[k];
        if (p.tool != tool) {
            job.push_back(fmt::format("mdi T{} M6 G43", p.tool));  // G43 after M6 in the same block: the new tool's length
            tool = p.tool;
        }
        const JointValues program = model.program(p.q, p.length);
        for (int i = 0; i < 3; ++i) EXPECT_NEAR(program[static_cast<int>(letters.find("XYZ"[i]))], p.tip[i], 1e-9);
        const JointValues joints = model.jointPositions(program, p.length);
        // Program words of joint positions: the module's forward kinematics, minus G54 and the tool offset.
        const auto words = [&](JointValues j) {
            controllers::linuxcnc::TrtPins pins = model.pins();
            pins.toolOffset = p.length;
            const int jx = static_cast<int>(letters.find('X')), jy = static_cast<int>(letters.find('Y')),
                      jz = static_cast<int>(letters.find('Z')), jt = static_cast<int>(letters.find(tiltAxis[0])),
                      jc = static_cast<int>(letters.find('C'));
            const auto w = controllers::linuxcnc::trtForward(*model.trt(), pins, {{j[jx], j[jy], j[jz]}, j[jt], j[jc]});
            j[jx] = w.xyz[0] - model.workOffset()[0];
            j[jy] = w.xyz[1] - model.workOffset()[1];
            j[jz] = w.xyz[2] - model.workOffset()[2] - p.length;
            return j;
        };
        JointValues j2 = joints, j1 = joints;
        for (int i = 0; i < j2.size(); ++i) {
            const bool rotary = m.axisLink(model.jointAxis(i)).kind == AxisKind::Rotary;
            (rotary ? j1 : j2)[i] -= p.dir * 1.0;
            if (!rotary) j1[i] = j2[i];
        }
        job.push_back("mdi " + move(letters, words(j1)));
        job.push_back(fmt::format("record a{}", k));
        job.push_back("mdi " + move(letters, words(j2)));
        job.push_back(fmt::format("record b{}", k));
        job.push_back("mdi " + move(letters, program));
        job.push_back(fmt::format("record p{}", k));
        expectedJoints.push_back(joints);
        programs.push_back(program);
    }

    // Joint mode (identity kinematics, switchkins-type 1 of the trt module: how LinuxCNC runs cnccomp testprog's
    // machine-coordinate programs): G54 and the tool offset off, the words are the joints; only the tables act.
    job.push_back("mdi G49");
    job.push_back("mdi G10 L2 P1 X0 Y0 Z0");
    job.push_back("mdi M68 E3 Q1");
    job.push_back("mdi M66 E0 L0");
    std::vector<JointValues> jointWords;
    const LinuxcncModel jointModel(m, files, controllers::linuxcnc::KinsMode::Joint);
    for (size_t k = 0; k < ps.size(); ++k) {
        const JointValues w = jointModel.program(ps[k].q, 0.0), before = w - JointValues::Constant(w.size(), ps[k].dir * 1.0);
        job.push_back("mdi " + move(letters, before));
        job.push_back("mdi " + move(letters, w));
        job.push_back(fmt::format("record j{}", k));
        jointWords.push_back(w);
    }

    // 3. The real LinuxCNC.
    std::vector<sim::Record> rec = sim::runJob(config, job, &f.seconds);
    EXPECT_EQ(rec.size(), 1 + 4 * ps.size());
    if (rec.size() != 1 + 4 * ps.size()) return f;
    // G54 after the whole emitted program.
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(rec[0].g5x[k], model.workOffset()[k], 1e-9) << "G54 " << "XYZ"[k] << " after cnccomp-g54.ngc";
    f.g54 = std::max({std::abs(rec[0].g5x[0] - model.workOffset()[0]), std::abs(rec[0].g5x[1] - model.workOffset()[1]),
                      std::abs(rec[0].g5x[2] - model.workOffset()[2])});
    EXPECT_GT(std::hypot(model.workOffset()[0], model.workOffset()[1], model.workOffset()[2]), 1e-3);  // not 0: the program ran
    for (size_t k = 0; k < ps.size(); ++k) {
        const sim::Record& r = rec[1 + 3 * ps.size() + k];
        EXPECT_EQ(r.label, fmt::format("j{}", k));
        const JointValues dirs = JointValues::Constant(config.joints, ps[k].dir);
        const JointValues predicted = jointModel.motorPositions(jointModel.jointPositions(jointWords[k], 0.0), dirs);
        JointValues motor(config.joints), pos(config.joints);
        for (int i = 0; i < config.joints; ++i) motor[i] = r.motorPosCmd[i], pos[i] = r.posCmd[i];
        f.jointMode = std::max(f.jointMode, (pos - jointWords[k]).cwiseAbs().maxCoeff());
        f.jointModeMotor = std::max(f.jointModeMotor, (motor - predicted).cwiseAbs().maxCoeff());
    }
    rec.erase(rec.begin() + 1 + 3 * ps.size(), rec.end());
    rec.erase(rec.begin());
    for (size_t k = 0; k < ps.size(); ++k) {
        const Pose& p = ps[k];
        const sim::Record &a = rec[3 * k], &b = rec[3 * k + 1], &r = rec[3 * k + 2];
        EXPECT_EQ(r.label, fmt::format("p{}", k));
        EXPECT_NEAR(r.toolOffset, p.length, 1e-12) << "motion.tooloffset.z at pose " << k;
        f.settled += r.settled;
        JointValues dirs = JointValues::Constant(config.joints, p.dir), motor(config.joints), pos(config.joints);
        AxisVector c = m.toController(p.q);
        for (int i = 0; i < config.joints; ++i) {
            const bool rotary = m.axisLink(model.jointAxis(i)).kind == AxisKind::Rotary;
            // The approach worked: the last move of every joint went in the pose's direction.
            const double last = rotary ? b.posCmd[i] - a.posCmd[i] : r.posCmd[i] - b.posCmd[i];
            EXPECT_NEAR(last, p.dir * 1.0, 1e-6) << "pose " << k << " joint " << i;
            pos[i] = r.posCmd[i];
            motor[i] = r.motorPosCmd[i];
            c[model.jointAxis(i)] = r.motorPosCmd[i] * (rotary ? kDeg : 1.0);
        }
        const JointValues predicted = model.motorPositions(expectedJoints[k], dirs);
        f.kinematics = std::max(f.kinematics, (pos - expectedJoints[k]).cwiseAbs().maxCoeff());
        f.motor = std::max(f.motor, (motor - predicted).cwiseAbs().maxCoeff());
        // The erroneous machine at LinuxCNC's motor positions.
        const AxisVector drive = m.fromController(c);
        const Vec3 tip = actual.toolPointInWorkpiece(drive, actual.toolPoint(p.length));
        f.tip = std::max(f.tip, (tip - p.tip).norm());
        f.tipBefore = std::max(f.tipBefore, (actual.toolPointInWorkpiece(p.q, actual.toolPoint(p.length)) - p.tip).norm());
        f.tipFull = std::max(f.tipFull, (full.toolPointInWorkpiece(drive, full.toolPoint(p.length)) - p.tip).norm());
        EXPECT_LT((tip - p.tip).norm(), 1e-4) << "pose " << k << ": tool tip off by " << (tip - p.tip).norm() / kUm << " um";
        ++f.poses;
    }
    std::cout << fmt::format("[linuxcnc oracle] {:<22} {} poses, LinuxCNC run {:.1f} s; LinuxCNC vs model: pos-cmd {:.1e}, "
                             "motor-pos-cmd {:.1e} (mm/deg); tool tip at LinuxCNC's motor positions: claimed {:.4f} um "
                             "(before {:.2f} um), full set {:.2f} um; comp filters settled {}/{}; G54 after cnccomp-g54.ngc "
                             "in AUTO off by {:.1e} mm; joint mode (identity kinematics): pos-cmd = words to {:.1e}, "
                             "motor-pos-cmd vs model {:.1e}\n",
                             machineName, f.poses, f.seconds, f.kinematics, f.motor, f.tip / kUm, f.tipBefore / kUm,
                             f.tipFull / kUm, f.settled, f.poses, f.g54, f.jointMode, f.jointModeMotor);
    return f;
}

void oracle(const std::string& machine, const std::string& deviations, const std::string& tilt) {
    if (const std::string why = sim::unavailableReason(); !why.empty()) GTEST_SKIP() << why;
    const Figures f = runOracle(machine, deviations, tilt);
    EXPECT_GE(f.poses, 20);
    EXPECT_LE(f.kinematics, 1e-4);
    EXPECT_LE(f.motor, 1e-4);
    EXPECT_LE(f.tip, 1e-4);
    EXPECT_GT(f.tipBefore, 10 * kUm);  // the deviations matter
    EXPECT_LE(f.g54, 1e-9);
    EXPECT_LE(f.jointMode, 1e-9);
    EXPECT_LE(f.jointModeMotor, 1e-4);
}

TEST(LinuxcncOracle, TableTableACMatchesTheRealLinuxcnc) { oracle("controllers-table-table-ac", "controllers-table-table-ac", "A"); }

TEST(LinuxcncOracle, TableTableBCWithToolSideOffsetsMatchesTheRealLinuxcnc) { oracle("table-table-bc-offsets", "table-table-bc-offsets-truth", "B"); }

TEST(LinuxcncOracle, IniMergeReplacesKeysAndAddsSections) {
    const std::string merged = sim::mergeIni("[KINS]\nKINEMATICS = trivkins\nJOINTS = 3\n\n[JOINT_0]\nTYPE = LINEAR\n",
                                             "# c\n[KINS]\nKINEMATICS = xyzac-trt-kins coordinates=XYZAC\n[JOINT_0]\nCOMP_FILE = X.comp\n"
                                             "[JOINT_4]\nCOMP_FILE = C.comp\n");
    EXPECT_EQ(merged, "[KINS]\nKINEMATICS = xyzac-trt-kins coordinates=XYZAC\nJOINTS = 3\n\n[JOINT_0]\nTYPE = LINEAR\n"
                      "COMP_FILE = X.comp\n\n[JOINT_4]\nCOMP_FILE = C.comp\n");
}

}  // namespace
}  // namespace cnccomp::test
