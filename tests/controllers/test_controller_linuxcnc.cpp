// LinuxCNC backend: trt pins against the exact model (LinuxCNC's frame, tool-side offsets, machine-zero, tool lengths),
// emit → apply on the erroneous machine (≥ 90 % less tip error for what the backend claims, C beyond ±360°), table
// rules (travel coverage, 256 lines, LinuxCNC's lookup), goldens parsed back, readers, CLI. The real LinuxCNC is the
// oracle of tests/linuxcnc (a test program of its own).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <map>
#include <sstream>

#include "cnccomp/error.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/kinematics.hpp"
#include <fmt/format.h>
#include "controllers/common/evaluate.hpp"
#include "controllers/common/files.hpp"
#include "controllers/linuxcnc/comp_table.hpp"
#include "controllers/linuxcnc/component_route.hpp"
#include "controllers/linuxcnc/linuxcnc_apply.hpp"
#include "controllers/linuxcnc/config_files.hpp"
#include "controllers/linuxcnc/linuxcnc_plan.hpp"
#include "test_support.hpp"
#include "test_controller_common_support.hpp"

namespace cnccomp::controllers {
using namespace cnccomp::controllers::common;
using namespace cnccomp::io;
namespace {

using namespace testing;

const std::vector<Sample> kSamples = {{"multitasking", "multitasking-truth"},
                                      {"controllers-table-table-ac", "controllers-table-table-ac"},
                                      {"controllers-tilting-head-b", "controllers-tilting-head-b"},
                                      {"table-table-bc-offsets", "table-table-bc-offsets-truth"}};

/// The pins-and-tables route (backend linuxcnc-pins); the component route has its tests further down.
EmitResult emitSample(const Sample& s, const DeviationSet& d) { return testing::emitSample("linuxcnc-pins", s, d); }

/// What the pins route compensates in tool-tip mode: its compensated list and the NOT-compensated entries that say
/// "tool-tip mode only" (the trt pins and the G54).
DeviationSet claimedInToolTipMode(const DeviationSet& d, const EmitResult& r) {
    EmitResult notInToolTip = r;
    std::erase_if(notInToolTip.notCompensated,
                  [](const Coverage& c) { return c.note.starts_with(linuxcnc::kToolTipModeOnly); });
    return claimedOnly(d, notInToolTip);
}

/// The pins route's apply model in the mode its pins act in: tool-tip mode on a trt machine, joint mode otherwise.
std::unique_ptr<AppliedCompensation> pinsInToolTipMode(const MachineModel& m, const std::vector<OutputFile>& files) {
    using namespace linuxcnc;
    return std::make_unique<LinuxcncModel>(m, files, matchTrt(m) ? KinsMode::ToolTip : KinsMode::Joint);
}

/// Workspace samples, and the same again with every modulo axis two turns up and three turns down (LinuxCNC looks
/// its tables up at the raw joint position: C = 725° is not C = 5°).
std::vector<AxisVector> samplesWithTurns(const MachineModel& m, int perAxis) {
    std::vector<AxisVector> out = workspaceSamples(m, perAxis);
    const size_t n = out.size();
    for (double turns : {2.0, -3.0})
        for (size_t i = 0; i < n; ++i) {
            AxisVector q = out[i];
            for (int a = 0; a < m.axisCount(); ++a)
                if (m.axisLink(a).modulo) q[a] += turns * 2 * kPi;
            out.push_back(q);
        }
    return out;
}

TEST(ControllerLinuxcnc, TrtFormulasInvertAndPinsReproduceTheExactTable) {
    using namespace linuxcnc;
    const TrtPins pins{1.5, -2.0, 3.0, 0.7, -0.4, 0.9, 12.0};
    for (TrtType t : {TrtType::AC, TrtType::BC})
        for (double tilt : {-70.0, 0.0, 35.0})
            for (double c : {-150.0, 10.0, 200.0}) {
                const TrtPose j{{12.5, -40.0, 81.0}, tilt, c};
                const TrtPose back = trtInverse(t, pins, trtForward(t, pins, j));
                for (int k = 0; k < 3; ++k) EXPECT_NEAR(back.xyz[k], j.xyz[k], 1e-10);
            }
    EXPECT_EQ(matchTrt(machine("table-table-ac")), TrtType::AC);
    EXPECT_EQ(matchTrt(machine("table-table-bc-offsets")), TrtType::BC);
    EXPECT_FALSE(matchTrt(machine("multitasking")));
    EXPECT_FALSE(matchTrt(machine("tilting-head-b")));
    // Oracle: the exact kinematics. With the pins in LinuxCNC's frame, trtfuncs' forward of the joint positions
    // (machine coordinates from machine zero, tool-offset = tool length) is the tool tip in the erroneous workpiece
    // frame plus the G54 of cnccomp-g54.ngc plus the tool offset (0, 0, L), for every pose and tool length: so the
    // module turns about the real axis lines, the tool-side offsets and machine-zero included (table-table-bc-offsets has
    // a spindle offset of 10 20 30 mm and machine-zero 50 410 560 mm).
    struct Case {
        std::string machine, tilt;
        std::vector<std::pair<std::string, double>> errors;
    };
    for (const Case& cs : {Case{"table-table-ac", "A", {{"EY0A", 0.03}, {"EZ0A", -0.02}, {"EX0C", 0.015}, {"EY0C", -0.025}}},
                           Case{"table-table-bc-offsets", "B", {{"EX0B", 0.03}, {"EZ0B", -0.02}, {"EX0C", 0.015}, {"EY0C", -0.025}}}}) {
        const MachineModel& m = machine(cs.machine);
        const TrtType type = *matchTrt(m);
        DeviationSet d(m);
        for (const auto& [name, v] : cs.errors) d.set(name, v);
        const Kinematics k(m, d);
        const Vec3 g54 = trtWorkOffset(m, &d);
        const int ax = m.requireAxis("X"), ay = m.requireAxis("Y"), az = m.requireAxis("Z"), at = m.requireAxis(cs.tilt),
                  ac = m.requireAxis("C");
        for (double length : {0.0, 80.0})
            for (double tilt : {-1.2, 0.0, 0.7})
                for (double c : {-12.5, 0.4, 7.0}) {
                    AxisVector q(m.axisCount());
                    q[at] = tilt;
                    q[ac] = c;
                    q[ax] = 120;
                    q[ay] = 75;
                    q[az] = 210;
                    const AxisVector j = m.toController(q);
                    TrtPins p = trtPins(m, type, &d);
                    p.toolOffset = length;
                    const TrtPose w = trtForward(type, p, {{j[ax], j[ay], j[az]}, j[at] / kDeg, j[ac] / kDeg});
                    const Vec3 tip = k.toolPointInWorkpiece(q, k.toolPoint(length));
                    EXPECT_NEAR(w.xyz[0], tip.x() + g54.x(), 1e-10) << cs.machine;
                    EXPECT_NEAR(w.xyz[1], tip.y() + g54.y(), 1e-10) << cs.machine;
                    EXPECT_NEAR(w.xyz[2], tip.z() + g54.z() + length, 1e-10) << cs.machine;
                }
    }
    // The nominal pins of table-table-bc-offsets in LinuxCNC's frame, by hand from its description: C line through
    // (250 + 15, 100 + 0, 180 − 60) of the bed, tool reference point at joint 0: (10, 20, 30) + (50, 410, 560).
    const TrtPins n = trtPins(machine("table-table-bc-offsets"), TrtType::BC, nullptr);
    EXPECT_NEAR(n.xRotPoint, 205, 1e-12);
    EXPECT_NEAR(n.yRotPoint, -330, 1e-12);
    EXPECT_NEAR(n.zRotPoint, -470, 1e-12);
    EXPECT_NEAR(n.xOffset, -15, 1e-12);
    EXPECT_NEAR(n.zOffset, 60, 1e-12);
}

TEST(ControllerLinuxcnc, Linuxcnc210XyzbcInverseDiffersAsTheFilesSay) {
    // Transcription of xyzbcKinematicsInverse of LinuxCNC master (2.10, trtfuncs.c with conventional-directions = 0,
    // the default): the same rotation as 2.9, dpx = −cos(B)·dx + sin(B)·dz + dx, dpz = −sin(B)·dx − cos(B)·dz + dz.
    // README.txt of an xyzbc emit says the joints differ from 2.9's by 2·|sin B|·(z-offset + tool-offset) in X and
    // 2·|sin B|·|x-offset| in Z: checked here against the 2.9 transcription (trt_kins.cpp), signs included.
    using namespace linuxcnc;
    const TrtPins p{205, -330, -470, -15, 0, 60, 100};
    for (double b : {-80.0, -20.0, 35.0})
        for (double c : {-400.0, 30.0}) {
            const TrtPose w{{12, -34, 56}, b, c};
            const double br = b * kDeg, cr = c * kDeg, con = -1;
            const double x = w.xyz[0] - p.xRotPoint, y = w.xyz[1] - p.yRotPoint, z = w.xyz[2] - p.zRotPoint;
            const double dx = p.xOffset, dz = p.zOffset + p.toolOffset;
            const double dpx = -std::cos(br) * dx + std::sin(br) * dz + dx, dpz = -std::sin(br) * dx - std::cos(br) * dz + dz;
            const double mx = std::cos(cr) * std::cos(br) * x + con * std::sin(cr) * std::cos(br) * y - con * std::sin(br) * z + dpx + p.xRotPoint;
            const double mz = con * std::cos(cr) * std::sin(br) * x + std::sin(cr) * std::sin(br) * y + std::cos(br) * z + dpz + p.zRotPoint;
            const TrtPose j = trtInverse(TrtType::BC, p, w);
            EXPECT_NEAR(mx - j.xyz[0], 2 * std::sin(br) * dz, 1e-9);
            EXPECT_NEAR(mz - j.xyz[2], -2 * std::sin(br) * dx, 1e-9);
        }
}

TEST(ControllerLinuxcnc, PinsInTheDescriptionsFrameWouldMissByTensOfMillimetres) {
    // What the review found: pins in the machine-XML frame, blind to the tool-side offset. Rewrite cnccomp.hal that
    // way and the apply model (the LinuxCNC transcription) puts the tip tens of mm off; the emitted pins do not.
    const Sample& s = kSamples[3];
    const MachineModel& m = machine(s.machine);
    const DeviationSet d = deviations(s);
    const EmitResult r = emitSample(s, d);
    const auto samples = workspaceSamples(m, 3);
    const DeviationSet claimed = claimedInToolTipMode(d, r);
    const CompensationFigures good = evaluateCompensation(m, claimed, *pinsInToolTipMode(m, r.files), samples, 50.0);
    EXPECT_LT(good.maxAfter, 1e-4);
    std::vector<OutputFile> wrong = r.files;
    for (OutputFile& f : wrong)
        if (f.name == "cnccomp.hal") {
            const linuxcnc::TrtPins p = *linuxcnc::parseHal(f.content, f.name, "xyzbc-trt-kins");
            f.content = fmt::format("setp xyzbc-trt-kins.x-rot-point {}\nsetp xyzbc-trt-kins.y-rot-point {}\n"
                                    "setp xyzbc-trt-kins.z-rot-point {}\nsetp xyzbc-trt-kins.x-offset {}\nsetp xyzbc-trt-kins.z-offset {}\n",
                                    p.xRotPoint + 60, p.yRotPoint + 430, p.zRotPoint + 590, p.xOffset, p.zOffset);
        }
    const CompensationFigures bad = evaluateCompensation(m, claimed, *pinsInToolTipMode(m, wrong), samples, 50.0);
    EXPECT_GT(bad.maxAfter, 10.0);
}

TEST(ControllerLinuxcnc, CompensatesWhatItClaimsByAtLeastNinetyPercent) {
    const Backend& b = backend("linuxcnc-pins");
    for (const Sample& s : kSamples) {
        const MachineModel& m = machine(s.machine);
        const DeviationSet all = deviations(s);
        const EmitResult r = emitSample(s, all);
        ASSERT_FALSE(r.compensated.empty() && claimedInToolTipMode(all, r).present == DeviationSet(m).present) << s.machine;
        const DeviationSet claimed = claimedInToolTipMode(all, r);
        const auto samples = samplesWithTurns(m, 5);
        const CompensationFigures f = evaluateCompensation(m, claimed, *pinsInToolTipMode(m, b.emit({m, claimed, "d.csv", "2024-01-01"}).files),
                                                           samples, 100.0);
        const CompensationFigures g = evaluateCompensation(m, all, *pinsInToolTipMode(m, r.files), samples, 100.0);
        std::cout << fmt::format("[linuxcnc] {:<28} claimed: max {:8.3f} -> {:7.3f} um, rms {:7.3f} -> {:6.3f} um | "
                                 "full set: max {:8.3f} -> {:7.3f} um ({} points)\n",
                                 s.machine, f.maxBefore / kUm, f.maxAfter / kUm, f.rmsBefore / kUm, f.rmsAfter / kUm,
                                 g.maxBefore / kUm, g.maxAfter / kUm, f.points);
        EXPECT_GT(f.maxBefore, 5 * kUm) << s.machine;
        EXPECT_LT(f.maxAfter, 0.1 * f.maxBefore) << s.machine;
        EXPECT_LT(f.maxAfter, 0.05 * kUm) << s.machine;  // exact up to the tables' interpolation
        EXPECT_LT(g.maxAfter, g.maxBefore) << s.machine;
        // Every present deviation is listed exactly once.
        size_t present = 0;
        for (char p : all.present) present += p != 0;
        EXPECT_EQ(r.compensated.size() + r.notCompensated.size(), present) << s.machine;
    }
}

TEST(ControllerLinuxcnc, TablesKeepTheLinuxcncRules) {
    for (const Sample& s : kSamples) {
        const MachineModel& m = machine(s.machine);
        const EmitResult r = emitSample(s, deviations(s));
        for (const OutputFile& f : r.files) {
            if (!f.name.ends_with(".comp")) continue;
            // Independent reading: every line exactly three numbers, at most 256 lines, strictly increasing.
            std::istringstream in(f.content);
            std::string line;
            std::vector<std::array<double, 3>> rows;
            while (std::getline(in, line)) {
                std::istringstream ls(line);
                std::array<double, 3> v{};
                std::string extra;
                ASSERT_TRUE(ls >> v[0] >> v[1] >> v[2]) << f.name << ": " << line;
                ASSERT_FALSE(ls >> extra) << f.name << ": " << line;
                if (!rows.empty()) {
                    ASSERT_GT(v[0], rows.back()[0]) << f.name;
                }
                rows.push_back(v);
            }
            EXPECT_GE(rows.size(), 2u);
            EXPECT_LE(rows.size(), 256u) << f.name;
            // The table covers the axis' whole travel in LinuxCNC's coordinates (command − machine-zero).
            const Link& l = m.axisLink(m.requireAxis(f.name.substr(0, f.name.size() - 5)));
            const double unit = l.kind == AxisKind::Rotary ? kDeg : 1.0;
            EXPECT_NEAR(rows.front()[0], (l.min - l.machineZero) / unit, 1e-6) << f.name;
            EXPECT_NEAR(rows.back()[0], (l.max - l.machineZero) / unit, 1e-6) << f.name;
        }
    }
    // A table over 256 lines is refused.
    linuxcnc::CompTable t;
    for (int i = 0; i < 257; ++i) t.nominal.push_back(i), t.forward.push_back(0), t.reverse.push_back(0);
    EXPECT_THROW(linuxcnc::formatCompTable(t, "x.comp"), ModelError);
}

TEST(ControllerLinuxcnc, TableTrimsMatchTheComponentErrors) {
    // X.comp of the table-table variant holds EXX at its table nodes: trim(x) = −EXX(x) to first order, and
    // x + trim + EXX(x + trim) = x exactly (the trim solves the axis' own error).
    const Sample& s = kSamples[1];
    const MachineModel& m = machine(s.machine);
    const DeviationSet d = deviations(s);
    const EmitResult r = emitSample(s, d);
    const auto t = linuxcnc::parseCompTable(requireFile(r.files, "X.comp", "test").content, "X.comp");
    const DeviationDef& exx = m.deviations[m.deviationIndex("EXX")];
    ASSERT_EQ(t.nominal.size(), 11u);
    for (size_t i = 0; i < t.nominal.size(); ++i) {
        const double x = t.nominal[i], q = x + t.forward[i];
        EXPECT_NEAR(q + exx.basis.evaluate(q, d.values.data() + exx.offset, false), x, 2e-6);
        EXPECT_NEAR(t.forward[i], -exx.basis.evaluate(x, d.values.data() + exx.offset, false), 1e-6);
    }
}

TEST(ControllerLinuxcnc, GoldenFilesAreReproducedAndReadBack) {
    for (const Sample& s : kSamples) {
        const EmitResult r = emitSample(s, deviations(s));
        const std::vector<OutputFile> golden = compareWithGolden("linuxcnc", s.machine, r);
        // The golden files read back into a working compensation.
        const auto comp = backend("linuxcnc-pins").apply(machine(s.machine), golden);
        ASSERT_NE(comp, nullptr);
        const AxisVector q = AxisVector::Zero(machine(s.machine).axisCount());
        EXPECT_TRUE(comp->driveCommands(q).allFinite());
    }
}

TEST(ControllerLinuxcnc, ReadersNameFileAndLine) {
    using namespace linuxcnc;
    const auto line = [](auto f) { return inputErrorLine(f); };
    EXPECT_EQ(line([] { parseCompTable("0 0 0\n10 0.001\n", "x.comp"); }), 2);
    EXPECT_EQ(line([] { parseCompTable("0 0 0\n10 0 0\n10 0 0\n", "x.comp"); }), 3);
    EXPECT_EQ(line([] { parseCompTable("0 0 0\n# comment\n", "x.comp"); }), 2);
    EXPECT_EQ(line([] { parseCompTable("0 nan 0\n1 0 0\n", "x.comp"); }), 1);
    EXPECT_EQ(line([] { parseIni("[KINS]\nKINEMATICS = trivkins coordinates=XYZ\n[JOINT_0]\nCOMP_FILE_TYPE = 2\n", "a.ini"); }), 4);
    EXPECT_EQ(line([] { parseWorkOffset("; c\nG10 L2 P1 X1 Y2\n", "g.ngc"); }), 2);
    EXPECT_EQ(line([] { parseWorkOffset("G10 L2 P1 X1 Y2 Q3\n", "g.ngc"); }), 1);
    EXPECT_EQ(line([] { parseWorkOffset("G10 L2 P1 X1 Y2 Zabc\n", "g.ngc"); }), 1);
    EXPECT_EQ(line([] { parseWorkOffset("; only comments\nM2\n", "g.ngc"); }), 0);
    EXPECT_EQ(parseWorkOffset("(x)\nG10 L2 P1 X1.5 Y-2 Z3 ; c\nM2\n", "g.ngc"), (std::array<double, 3>{1.5, -2, 3}));
    EXPECT_EQ(line([] { parseIni("[KINS]\nKINEMATICS trivkins\n", "a.ini"); }), 2);
    EXPECT_EQ(line([] { parseHal("setp xyzac-trt-kins.w-offset 1\n", "a.hal", "xyzac-trt-kins"); }), 1);
    EXPECT_EQ(line([] { parseHal("# ok\nsetp xyzac-trt-kins.y-offset one\n", "a.hal", "xyzac-trt-kins"); }), 2);
    // A missing table file is named.
    const Sample& s = kSamples[1];
    EmitResult r = emitSample(s, deviations(s));
    std::erase_if(r.files, [](const OutputFile& f) { return f.name == "C.comp"; });
    try {
        backend("linuxcnc").apply(machine(s.machine), r.files);
        FAIL() << "missing C.comp accepted";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("C.comp"), std::string::npos);
    }
    // The files of one machine do not fit another.
    const EmitResult other = emitSample(kSamples[0], deviations(kSamples[0]));
    EXPECT_THROW(backend("linuxcnc").apply(machine(s.machine), other.files), InputError);
}

TEST(ControllerLinuxcnc, CompTableLookupFollowsLinuxcnc) {
    // control.c compute_screw_comp / motion.c: forward column moving +, reverse moving −, linear in between, end
    // values held beyond the ends, no modulo; usrmotintf.cc: type 0 holds actual positions (trim = nominal − value).
    using namespace linuxcnc;
    const CompTable t = parseCompTable("-10 0.01 -0.01\n0 0.02 0\n10 0.04 0.01\n", "t.comp");
    EXPECT_DOUBLE_EQ(t.trim(5, 1), 0.03);
    EXPECT_DOUBLE_EQ(t.trim(5, -1), 0.005);
    EXPECT_DOUBLE_EQ(t.trim(5, 0), 0.0175);
    EXPECT_DOUBLE_EQ(t.trim(-20, 1), 0.01);
    EXPECT_DOUBLE_EQ(t.trim(-10, -1), -0.01);
    EXPECT_DOUBLE_EQ(t.trim(10, 1), 0.04);
    EXPECT_DOUBLE_EQ(t.trim(370, -1), 0.01);
    const CompTable a = fromActualPositions(parseCompTable("0 0.001 -0.001\n100 100.002 99.999\n", "a.comp"));
    EXPECT_NEAR(a.trim(0, 1), -0.001, 1e-15);
    EXPECT_NEAR(a.trim(100, -1), 0.001, 1e-12);
}

/// A machine written into a scratch folder: C table (modulo, travel ±turns·360°) with a Fourier positioning
/// error, X Y Z slides; `extra` goes into the A axis (e.g. machine-zero).
MachineModel fourierMachine(const test::ScratchDir& dir, int turns, const std::string& extra = "") {
    const std::string path = dir.file(fmt::format("m{}.xml", turns));
    test::writeText(path, fmt::format(R"(<machine name="fourier">
<workpiece>
  <axis name="A" type="rotary" direction="1 0 0" min="-90" max="90" {}/>
  <axis name="C" type="rotary" direction="0 0 1" min="-{}" max="{}" modulo="true"/>
</workpiece>
<tool direction="0 0 -1">
  <axis name="X" type="linear" direction="1 0 0" min="-300" max="300"/>
  <axis name="Y" type="linear" direction="0 1 0" min="-300" max="300"/>
  <axis name="Z" type="linear" direction="0 0 1" min="-300" max="300"/>
</tool>
<deviations><component name="ECC" link="C" component="c" basis="fourier" order="2"/></deviations>
</machine>
)", extra, 360 * turns, 360 * turns));
    return readMachineXml(path);
}

TEST(ControllerLinuxcnc, RotaryTablesCoverTheTravelAtASpacingThatDividesATurn) {
    test::ScratchDir dir("linuxcnc-fourier");
    for (int turns : {1, 10}) {
        const MachineModel m = fourierMachine(dir, turns);
        DeviationSet d(m);
        const DeviationDef& ecc = m.deviations[m.deviationIndex("ECC")];
        d.values.segment(ecc.offset, 4) << 8 * kArcsec, -5 * kArcsec, 3 * kArcsec, 2 * kArcsec;
        d.present[m.deviationIndex("ECC")] = 1;
        const EmitResult r = backend("linuxcnc-pins").emit({m, d, "d.csv", "2024-01-01"});
        const linuxcnc::CompTable t = linuxcnc::parseCompTable(requireFile(r.files, "C.comp", "test").content, "C.comp");
        // ±360°: 3° (241 lines); ±3600°: 30° (241 lines); every point a multiple of the spacing, ends at the travel.
        const double h = turns == 1 ? 3.0 : 30.0;
        EXPECT_EQ(t.nominal.size(), static_cast<size_t>(2 * 360 * turns / h + 1));
        for (double n : t.nominal) EXPECT_NEAR(std::remainder(n, h), 0.0, 1e-9) << n;
        EXPECT_EQ(t.nominal.front(), -360.0 * turns);
        EXPECT_EQ(t.nominal.back(), 360.0 * turns);
        // The same trim every turn, at the raw position (7 turns apart as LinuxCNC sees them).
        if (turns == 10) {
            for (double c : {-2.5, 17.0, 133.3}) EXPECT_NEAR(t.trim(c + 7 * 360.0), t.trim(c), 1e-7) << c;
        }
        // The interpolation error is stated in every header.
        EXPECT_NE(requireFile(r.files, "README-pins.txt", "test").content.find("C.comp: 241 points"), std::string::npos);
        EXPECT_NE(requireFile(r.files, "README-pins.txt", "test").content.find("largest interpolation error"), std::string::npos);
    }
    // No finite travel: refused with the reason.
    std::string xml = test::readText(dir.file("m1.xml"));
    xml.replace(xml.find(R"(min="-360" max="360" )"), 21, "");
    test::writeText(dir.file("inf.xml"), xml);
    const MachineModel inf = readMachineXml(dir.file("inf.xml"));
    DeviationSet di(inf);
    di.values[inf.deviations[0].offset] = 1e-5;
    di.present[0] = 1;
    try {
        backend("linuxcnc-pins").emit({inf, di, "d.csv", "2024-01-01"});
        FAIL() << "infinite travel accepted";
    } catch (const ModelError& e) {
        EXPECT_NE(std::string(e.what()).find("travel"), std::string::npos) << e.what();
    }
}

TEST(ControllerLinuxcnc, TrtNeedsTheRotaryJointsZeroedWhereTheTableIsLevel) {
    test::ScratchDir dir("linuxcnc-rotary-zero");
    const MachineModel m = fourierMachine(dir, 1, R"(machine-zero="90")");
    try {
        backend("linuxcnc-pins").emit({m, DeviationSet(m), "d.csv", "2024-01-01"});
        FAIL() << "a tilt axis with machine-zero 90 accepted";
    } catch (const ModelError& e) {
        EXPECT_NE(std::string(e.what()).find("machine-zero"), std::string::npos) << e.what();
    }
}

TEST(ControllerLinuxcnc, FilesSayVersionFrameBacklashAndHowToMerge) {
    for (const Sample& s : kSamples) {
        const EmitResult r = emitSample(s, deviations(s));
        const bool trt = linuxcnc::matchTrt(machine(s.machine)).has_value();
        for (const OutputFile& f : r.files) {
            if (f.name.ends_with(".comp")) continue;
            EXPECT_NE(f.content.find("LinuxCNC 2.9"), std::string::npos) << s.machine << "/" << f.name;
            EXPECT_NE(f.content.find("ignores BACKLASH"), std::string::npos) << s.machine << "/" << f.name;
            if (trt) {
                EXPECT_NE(f.content.find("pins: ABSOLUTE, LinuxCNC's frame"), std::string::npos) << s.machine << "/" << f.name;
            }
        }
        const std::string readme = requireFile(r.files, "README-pins.txt", "test").content;
        EXPECT_NE(readme.find("add +b/2 to every forward trim and -b/2 to every reverse trim"), std::string::npos) << s.machine;
        const std::string ini = requireFile(r.files, "cnccomp.ini", "test").content;
        EXPECT_EQ(ini.find("WRAPPED_ROTARY"), std::string::npos) << s.machine;  // tables cover the travel instead
        size_t joints = 0, warnings = 0;
        for (size_t at = 0; (at = ini.find("COMP_FILE = ", at)) != std::string::npos; ++at) ++joints;
        for (size_t at = 0; (at = ini.find("does not apply BACKLASH to this joint", at)) != std::string::npos; ++at) ++warnings;
        EXPECT_EQ(joints, warnings) << s.machine;
        if (!trt) continue;
        EXPECT_NE(readme.find("They REPLACE your values of exactly these pins"), std::string::npos);
        EXPECT_NE(readme.find("x-rot-point y-rot-point z-rot-point"), std::string::npos);
        EXPECT_NE(readme.find("add the listed deltas"), std::string::npos);
        EXPECT_EQ(readme.find("2.10/master") != std::string::npos, *linuxcnc::matchTrt(machine(s.machine)) == linuxcnc::TrtType::BC);
        const std::string hal = requireFile(r.files, "cnccomp.hal", "test").content;
        EXPECT_NE(hal.find("# x-rot-point  nominal"), std::string::npos) << hal;
    }
}

TEST(ControllerLinuxcnc, ImplausibleValuesAreRefused) {
    const MachineModel& m = machine("multitasking");
    DeviationSet d(m);
    d.set("EX0C", 12.0);  // 12 mm: a unit mistake
    EXPECT_THROW(backend("linuxcnc-pins").emit({m, d, "x.csv", "2024-01-01"}), ModelError);
}

TEST(ControllerLinuxcnc, EmitCommandWritesFilesAndNeverAnInput) {
    test::ScratchDir dir("emit_linuxcnc");
    const std::string mfile = test::sourcePath("samples/machines/controllers-table-table-ac.xml");
    const std::string dfile = test::sourcePath("samples/deviations/controllers-table-table-ac.csv");
    const auto r = test::runCli("emit --controller linuxcnc --machine " + mfile + " --deviations " + dfile + " --out " +
                                dir.file("out") + " --date 2024-01-01");
    ASSERT_EQ(r.exitCode, 0) << r.out;
    EXPECT_NE(r.out.find("NOT compensated:"), std::string::npos);
    EXPECT_NE(r.out.find("EB0A"), std::string::npos);
    for (const char* f : {"X.comp", "C.comp", "cnccomp.ini", "cnccomp.hal", "cnccomp-g54.ngc", "README-pins.txt", "README.txt",
                          "cnccomp_kins.comp", "cnccomp-kins.ini", "cnccomp-kins.hal"})
        EXPECT_TRUE(std::filesystem::exists(dir.file(std::string("out/") + f))) << f;
    // emit says which route each file set is.
    EXPECT_NE(r.out.find("route 1, generated kinematics component"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("route 2, pins and tables"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("route 2 does not compensate EB0A"), std::string::npos) << r.out;
    // The deviation file sits where README.txt would go: nothing is written.
    std::filesystem::create_directories(dir.file("in"));
    std::filesystem::copy_file(dfile, dir.file("in/README.txt"));
    const auto bad = test::runCli("emit --controller linuxcnc --machine " + mfile + " --deviations " + dir.file("in/README.txt") +
                                  " --out " + dir.file("in"));
    EXPECT_EQ(bad.exitCode, 2) << bad.out;
    EXPECT_NE(bad.out.find("refusing to overwrite"), std::string::npos);
    EXPECT_FALSE(std::filesystem::exists(dir.file("in/X.comp")));
    EXPECT_EQ(test::readText(dir.file("in/README.txt")), test::readText(dfile));
    const auto unknown = test::runCli("emit --controller nosuch --machine " + mfile + " --deviations " + dfile + " --out " + dir.file("x"));
    EXPECT_EQ(unknown.exitCode, 2);
    EXPECT_NE(unknown.out.find("linuxcnc"), std::string::npos);
    const auto help = test::runCli("emit --help");
    EXPECT_NE(help.out.find("linuxcnc"), std::string::npos);
}


// ---- the component route -------------------------------------------------------------------------------

TEST(ControllerLinuxcnc, ComponentRouteHoldsEveryDeviationAndReadsItsPinsBack) {
    // Oracle: the exact kinematics of the erroneous machine (tool tip and axis at the drive commands the files give).
    // The generated component itself is checked against the real LinuxCNC in tests/linuxcnc.
    for (const Sample& s : kSamples) {
        const MachineModel& m = machine(s.machine);
        const DeviationSet all = deviations(s);
        const EmitResult r = testing::emitSample("linuxcnc", s, all);
        EXPECT_TRUE(r.notCompensated.empty()) << s.machine;
        size_t present = 0;
        for (char p : all.present) present += p != 0;
        EXPECT_EQ(r.compensated.size(), present) << s.machine;
        for (const char* f : {linuxcnc::kKinsSourceFile, linuxcnc::kKinsIniFile, linuxcnc::kKinsHalFile, "README.txt", "cnccomp.ini"})
            EXPECT_NE(findFile(r.files, f), nullptr) << s.machine << " " << f;
        const std::string readme = requireFile(r.files, "README.txt", "test").content;
        EXPECT_NE(readme.find("halcompile --install cnccomp_kins.comp"), std::string::npos);
        EXPECT_NE(readme.find("Route 2, pins and tables"), std::string::npos);
        const auto comp = backend("linuxcnc").apply(m, r.files);
        const auto* kins = dynamic_cast<const linuxcnc::KinsComponentModel*>(comp.get());
        ASSERT_NE(kins, nullptr) << s.machine;
        EXPECT_EQ((kins->values().values - all.values).cwiseAbs().maxCoeff(), 0.0) << s.machine;  // %.17g round trip
        const auto samples = workspaceSamples(m, 4);
        const CompensationFigures f = evaluateCompensation(m, all, *comp, samples, 0.0);
        std::cout << fmt::format("[linuxcnc component] {:<28} tip max {:8.3f} -> {:.2e} um, axis {:.2f} -> {:.2e} arcsec ({} points)\n",
                                 s.machine, f.maxBefore / kUm, f.maxAfter / kUm, f.maxAxisBefore / kArcsec, f.maxAxisAfter / kArcsec,
                                 f.points);
        EXPECT_GT(f.maxBefore, 5 * kUm) << s.machine;
        EXPECT_LT(f.maxAfter, 1e-6 * kUm * 1e3) << s.machine;  // 1 nm: the whole model
        // The model reads the values from the HAL file: zero one pin there and the drive commands change.
        std::vector<OutputFile> edited = r.files;
        for (OutputFile& file : edited)
            if (file.name == linuxcnc::kKinsHalFile) {
                // The first location deviation's pin (no coefficient index after its name): 10 um or 10 mrad more.
                size_t at = 0;
                for (;;) {
                    at = file.content.find("\nsetp cnccomp_kins.dev.", at + 1);
                    ASSERT_NE(at, std::string::npos);
                    const size_t pinEnd = file.content.find(' ', at + 6);
                    if (file.content.substr(at + 23, pinEnd - at - 23).find('.') == std::string::npos) break;
                }
                const size_t value = file.content.find(' ', at + 6) + 1, end = file.content.find('\n', value);
                file.content.replace(value, end - value, fmt::format("{:.17g}", std::stod(file.content.substr(value, end - value)) + 0.01));
            }
        const auto changed = backend("linuxcnc").apply(m, edited);
        double moved = 0;
        for (const AxisVector& q : samples) moved = std::max(moved, (changed->driveCommands(q) - comp->driveCommands(q)).cwiseAbs().maxCoeff());
        EXPECT_GT(moved, 1e-3) << s.machine;
        // The pins route of the same folder is verified when named.
        EXPECT_NE(dynamic_cast<const linuxcnc::LinuxcncModel*>(backend("linuxcnc-pins").apply(m, r.files).get()), nullptr);
    }
}

TEST(ControllerLinuxcnc, ComponentRouteReadersNameFileAndLine) {
    const Sample& s = kSamples[1];
    const MachineModel& m = machine(s.machine);
    const EmitResult r = testing::emitSample("linuxcnc", s, deviations(s));
    const auto withHal = [&](const std::string& extra) {
        std::vector<OutputFile> f = r.files;
        for (OutputFile& x : f)
            if (x.name == linuxcnc::kKinsHalFile) x.content += extra;
        return f;
    };
    DeviationSet v(m);
    const auto line = [&](const std::vector<OutputFile>& f) { return inputErrorLine([&] { linuxcnc::readKinsFiles(m, f, v); }); };
    const int n = static_cast<int>(splitLines(requireFile(r.files, linuxcnc::kKinsHalFile, "t").content).size());
    EXPECT_EQ(line(withHal("setp cnccomp_kins.dev.nosuch 1\n")), n + 1);
    EXPECT_EQ(line(withHal("setp cnccomp_kins.dev.ex0c 1\n")), n + 1);  // set twice
    EXPECT_EQ(line(withHal("setp cnccomp_kins.dev.ex0c x\n")), n + 1);
    EXPECT_EQ(line(withHal("loadusr halui\n")), n + 1);
}

TEST(ControllerLinuxcnc, TestProgramsRunInJointModeWhereTheTrtPinsDoNothing) {
    // A bug once found: verify ran cnccomp testprog's machine-coordinate programs through the trt pins (tool-tip mode) and
    // predicted 18.7 um where the real LinuxCNC, running them with the identity kinematics, gave 60.1 um.
    // 1. The programs say their mode.
    test::ScratchDir dir("linuxcnc-joint-mode");
    const std::string mfile = test::sourcePath("samples/machines/table-table-ac.xml");
    const std::string plan = test::sourcePath("samples/plans/table-table-ac-kinematic.xml");
    const std::string truth = test::sourcePath("samples/deviations/table-table-ac-truth.csv");
    const auto tp = test::runCli("testprog --machine " + mfile + " --plan " + plan + " --dialect linuxcnc --out " + dir.file("tp"));
    ASSERT_EQ(tp.exitCode, 0) << tp.out;
    int programs = 0;
    for (const auto& e : std::filesystem::directory_iterator(dir.file("tp")))
        if (e.path().extension() == ".ngc") {
            ++programs;
            EXPECT_NE(test::readText(e.path().string()).find("kinematics mode: joint"), std::string::npos) << e.path();
        }
    EXPECT_GT(programs, 0);
    // 2. Joint mode: the drives get the program words plus the table trims, whatever the pins and G54 say. Oracle:
    // the files' own tables read independently (parseCompTable), and the folder with the pins set to their nominal
    // values (the "tables only" run of the review) gives the same prediction.
    // The identified values copied (--copy-identified): fitted to the joint mode these programs run in, the pins would
    // be left at their nominal values (they act in tool-tip mode only), and this test is about what they do there.
    const auto emit = test::runCli("emit --controller linuxcnc-pins --copy-identified --machine " + mfile + " --deviations " +
                                   truth + " --out " + dir.file("pins") + " --date 2024-01-01");
    ASSERT_EQ(emit.exitCode, 0) << emit.out;
    const MachineModel m = readMachineXml(mfile);
    std::filesystem::copy(dir.file("pins"), dir.file("tables"));
    {
        std::string hal = test::readText(dir.file("pins/cnccomp.hal")), nominal;
        for (const auto& l : splitLines(hal)) {
            const std::string t(l.text);
            if (t.starts_with("# x-rot") || t.starts_with("# y-") || t.starts_with("# z-")) {
                const auto tok = tokens(t);  // "# pin nominal <value> delta ..."
                nominal += fmt::format("setp xyzac-trt-kins.{} {}\n", tok[1], tok[3]);
            }
        }
        ASSERT_FALSE(nominal.empty()) << hal;
        test::writeText(dir.file("tables/cnccomp.hal"), nominal);
        test::writeText(dir.file("tables/cnccomp-g54.ngc"), "G10 L2 P1 X0 Y0 Z0\nM2\n");
    }
    const auto verifyResidual = [&](const std::string& folder) {
        const auto v = test::runCli("verify --controller linuxcnc-pins --machine " + mfile + " --plan " + plan + " --compensation " +
                                    folder + " --truth " + truth);
        EXPECT_EQ(v.exitCode, 0) << v.out;
        const size_t at = v.out.find("residual (largest span after compensation): ");
        EXPECT_NE(at, std::string::npos) << v.out;
        return at == std::string::npos ? -1.0 : std::stod(v.out.substr(at + 44));
    };
    const double withPins = verifyResidual(dir.file("pins")), tablesOnly = verifyResidual(dir.file("tables"));
    std::cout << fmt::format("[linuxcnc joint mode] verify residual: emitted pins route {:.3f} um, tables-only folder {:.3f} um\n",
                             withPins, tablesOnly);
    EXPECT_EQ(withPins, tablesOnly);
    std::vector<OutputFile> files;
    for (const auto& e : std::filesystem::directory_iterator(dir.file("pins")))
        files.push_back({e.path().filename().string(), test::readText(e.path().string())});
    const auto joint = backend("linuxcnc-pins").apply(m, files);
    const linuxcnc::LinuxcncModel tip(m, files, linuxcnc::KinsMode::ToolTip);
    double differs = 0;
    for (const AxisVector& q : workspaceSamples(m, 3)) {
        const AxisVector c = m.toController(q);
        AxisVector expect = q;
        for (const char* axis : {"X", "Y", "Z", "A", "C"}) {
            const int a = m.requireAxis(axis);
            const OutputFile* table = findFile(files, std::string(axis) + ".comp");
            if (!table) continue;
            const double unit = m.axisLink(a).kind == AxisKind::Rotary ? kDeg : 1.0;
            expect[a] += linuxcnc::parseCompTable(table->content, table->name).trim(c[a] / unit) * unit;
        }
        EXPECT_LT((joint->driveCommands(q) - expect).cwiseAbs().maxCoeff(), 1e-12);
        differs = std::max(differs, (tip.driveCommands(q) - expect).cwiseAbs().maxCoeff());
    }
    EXPECT_GT(differs, 1e-3);  // in tool-tip mode the pins act (tens of um on this machine)
}

TEST(ControllerLinuxcnc, TableTableAxisTurningTheOtherWayIsRefusedByNameInThePinsRoute) {
    // A bug once found: C about −Z silently got trivkins, and README's "replace the key" swapped out the user's tool-tip
    // kinematics. The pins route refuses it naming the axis; the component route holds any structure.
    test::ScratchDir dir("linuxcnc-minus-z");
    std::string xml = test::readText(test::sourcePath("samples/machines/table-table-ac.xml"));
    const size_t c = xml.find("name=\"C\"");
    ASSERT_NE(c, std::string::npos);
    const size_t d = xml.find("direction=\"0 0 1\"", c);
    ASSERT_NE(d, std::string::npos) << "the sample's C axis direction";
    xml.replace(d, 17, "direction=\"0 0 -1\"");
    test::writeText(dir.file("m.xml"), xml);
    const MachineModel m = readMachineXml(dir.file("m.xml"));
    DeviationSet dev(m);
    dev.set("EX0C", 0.01);
    try {
        backend("linuxcnc-pins").emit({m, dev, "d.csv", "2024-01-01"});
        FAIL() << "C about -Z accepted by the pins route";
    } catch (const ModelError& e) {
        EXPECT_NE(std::string(e.what()).find("rotary axis C turns about -Z"), std::string::npos) << e.what();
    }
    const EmitResult r = backend("linuxcnc").emit({m, dev, "d.csv", "2024-01-01"});
    EXPECT_EQ(findFile(r.files, "cnccomp.ini"), nullptr);
    EXPECT_NE(requireFile(r.files, "README.txt", "t").content.find("not written for this machine: "), std::string::npos);
    const auto comp = backend("linuxcnc").apply(m, r.files);
    const CompensationFigures f = evaluateCompensation(m, dev, *comp, workspaceSamples(m, 3), 0.0);
    EXPECT_LT(f.maxAfter, 1e-6);
}

TEST(ControllerLinuxcnc, EveryEmittedProgramLineFitsLinuxcncsLineBuffer) {
    // LinuxCNC 2.9 aborts a program at a line of 254 characters or more, line end included ("Command too long",
    // interp_read.cc): the review's cnccomp-g54.ngc had comment lines of 258-270 characters and G54 stayed 0.
    for (const Sample& s : kSamples)
        for (const char* b : {"linuxcnc", "linuxcnc-pins"}) {
            const EmitResult r = testing::emitSample(b, s, deviations(s));
            for (const OutputFile& f : r.files) {
                if (!f.name.ends_with(".ngc")) continue;
                for (const auto& l : splitLines(f.content))
                    EXPECT_LE(l.text.size(), linuxcnc::kMaxProgramLine) << s.machine << "/" << f.name << ":" << l.number;
            }
        }
    EXPECT_EQ(linuxcnc::wrapCommentLines("; " + std::string(300, 'a') + "\nG0 X1\n", "; ", 100).find("G0 X1"), 318u);
    const std::string w = linuxcnc::wrapCommentLines("; one two three four five six\n", "; ", 14);
    EXPECT_EQ(w, "; one two\n;   three four\n;   five six\n");
}

}  // namespace
}  // namespace cnccomp::controllers
