// LinuxCNC backend: trt kinematics formulas against the exact model, emit → apply on the erroneous machine
// (≥ 90 % less tip error for what the backend claims), table format rules, goldens parsed back, readers, CLI.
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
#include "controllers/linuxcnc/config_files.hpp"
#include "controllers/linuxcnc/linuxcnc_plan.hpp"
#include "test_controller_common_support.hpp"

namespace cnccomp::controllers {
namespace {

using namespace testing;

const std::vector<Sample> kSamples = {{"multitasking", "multitasking-truth"},
                                      {"controllers-table-table-ac", "controllers-table-table-ac"},
                                      {"controllers-tilting-head-b", "controllers-tilting-head-b"}};

EmitResult emitSample(const Sample& s, const DeviationSet& d) { return testing::emitSample("linuxcnc", s, d); }

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
    // Pins from the pivot deviations: trtfuncs' forward of the joints is the tip in the erroneous table frame,
    // shifted by the rotation point (the LinuxCNC world frame coincides with the joints at A = C = 0).
    const MachineModel& m = machine("table-table-ac");
    ASSERT_EQ(matchTrt(m), TrtType::AC);
    EXPECT_FALSE(matchTrt(machine("multitasking")));
    EXPECT_FALSE(matchTrt(machine("tilting-head-b")));
    DeviationSet d(m);
    d.set("EY0A", 0.03);
    d.set("EZ0A", -0.02);
    d.set("EX0C", 0.015);
    d.set("EY0C", -0.025);
    const TrtPins p = trtPins(m, TrtType::AC, &d);
    const Kinematics k(m, d);
    for (double a : {-1.2, 0.0, 0.7})
        for (double c : {-2.5, 0.4, 3.0}) {
            AxisVector q(m.axisCount());
            q[m.requireAxis("A")] = a;
            q[m.requireAxis("C")] = c;
            q[m.requireAxis("X")] = 120;
            q[m.requireAxis("Y")] = -75;
            q[m.requireAxis("Z")] = 210;
            const Vec3 tip = k.toolPointInWorkpiece(q, Vec3::Zero());
            const TrtPose w = trtForward(TrtType::AC, p, {{120, -75, 210}, a / kDeg, c / kDeg});
            EXPECT_NEAR(w.xyz[0], tip.x() + p.xRotPoint, 1e-11);
            EXPECT_NEAR(w.xyz[1], tip.y() + p.yRotPoint, 1e-11);
            EXPECT_NEAR(w.xyz[2], tip.z() + p.zRotPoint, 1e-11);
        }
}

TEST(ControllerLinuxcnc, CompensatesWhatItClaimsByAtLeastNinetyPercent) {
    const Backend& b = backend("linuxcnc");
    for (const Sample& s : kSamples) {
        const MachineModel& m = machine(s.machine);
        const DeviationSet all = deviations(s);
        const EmitResult r = emitSample(s, all);
        ASSERT_FALSE(r.compensated.empty()) << s.machine;
        const DeviationSet claimed = claimedOnly(all, r);
        const auto samples = workspaceSamples(m, 5);
        const CompensationFigures f = emitApplyEvaluate(b, m, claimed, samples, 100.0);
        const CompensationFigures g = emitApplyEvaluate(b, m, all, samples, 100.0);
        std::cout << fmt::format("[linuxcnc] {:<28} claimed: max {:8.3f} -> {:7.3f} um, rms {:7.3f} -> {:6.3f} um | "
                                 "full set: max {:8.3f} -> {:7.3f} um ({} points)\n",
                                 s.machine, f.maxBefore / kUm, f.maxAfter / kUm, f.rmsBefore / kUm, f.rmsAfter / kUm,
                                 g.maxBefore / kUm, g.maxAfter / kUm, f.points);
        EXPECT_GT(f.maxBefore, 5 * kUm) << s.machine;
        EXPECT_LT(f.maxAfter, 0.1 * f.maxBefore) << s.machine;
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
            const Link& l = m.axisLink(m.requireAxis(f.name.substr(0, f.name.size() - 5)));
            if (l.modulo) {  // closes on itself over one turn
                EXPECT_EQ(rows.front()[0], 0.0);
                EXPECT_EQ(rows.back()[0], 360.0);
                EXPECT_EQ(rows.front()[1], rows.back()[1]);
                EXPECT_EQ(rows.front()[2], rows.back()[2]);
            } else {
                EXPECT_NEAR(rows.front()[0], l.min / (l.kind == AxisKind::Rotary ? kDeg : 1.0), 1e-6);
                EXPECT_NEAR(rows.back()[0], l.max / (l.kind == AxisKind::Rotary ? kDeg : 1.0), 1e-6);
            }
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
        const auto comp = backend("linuxcnc").apply(machine(s.machine), golden);
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
    EXPECT_EQ(line([] { parseIni("[KINS]\nKINEMATICS = trivkins coordinates=XYZ\n[JOINT_0]\nCOMP_FILE_TYPE = 0\n", "a.ini"); }), 4);
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

TEST(ControllerLinuxcnc, ImplausibleValuesAreRefused) {
    const MachineModel& m = machine("multitasking");
    DeviationSet d(m);
    d.set("EX0C", 12.0);  // 12 mm: a unit mistake
    EXPECT_THROW(backend("linuxcnc").emit({m, d, "x.csv", "2024-01-01"}), ModelError);
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
    for (const char* f : {"X.comp", "C.comp", "cnccomp.ini", "cnccomp.hal", "README.txt"})
        EXPECT_TRUE(std::filesystem::exists(dir.file(std::string("out/") + f))) << f;
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

}  // namespace
}  // namespace cnccomp::controllers
