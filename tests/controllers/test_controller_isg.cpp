// ISG / TF5280 backend: emit → apply on the erroneous machine (≥ 90 % less tip error for what it claims, with the
// tool length the controller applies), ISG_CSV syntax read back independently, goldens, readers, limits.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <sstream>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "controllers/common/evaluate.hpp"
#include "controllers/isg/isg_files.hpp"
#include "controllers/isg/isg_model.hpp"
#include "controller_test_util.hpp"
#include "test_controller_common_support.hpp"

namespace cnccomp::controllers {
using namespace cnccomp::controllers::common;
using namespace cnccomp::io;
namespace {

using namespace testing;

const std::vector<Sample> kSamples = {{"multitasking", "multitasking-truth"},
                                      {"controllers-table-table-ac", "controllers-table-table-ac"},
                                      {"controllers-tilting-head-b", "controllers-tilting-head-b"}};

EmitResult emitSample(const Sample& s, const DeviationSet& d) { return testing::emitSample("isg", s, d); }

TEST(ControllerIsg, CompensatesWhatItClaimsByAtLeastNinetyPercent) {
    const Backend& b = backend("isg");
    for (const Sample& s : kSamples) {
        const MachineModel& m = machine(s.machine);
        const DeviationSet all = deviations(s);
        const EmitResult r = emitSample(s, all);
        const DeviationSet claimed = claimedOnly(all, r);
        // Away from the singular orientations at the ends/middle of the rotary travel, and at them.
        for (int per : {4, 5}) {
            const auto samples = workspaceSamples(m, per);
            for (double L : {0.0, 150.0}) {
                const CompensationFigures f = emitApplyEvaluate(b, m, claimed, samples, L);
                std::cout << fmt::format("[isg] {:<28} L={:5.1f} grid {}^n: max {:8.3f} -> {:7.3f} um, rms {:7.3f} -> {:6.3f} um, "
                                         "axis {:6.2f} -> {:5.2f} arcsec ({} points)\n",
                                         s.machine, L, per, f.maxBefore / kUm, f.maxAfter / kUm, f.rmsBefore / kUm,
                                         f.rmsAfter / kUm, f.maxAxisBefore / kArcsec, f.maxAxisAfter / kArcsec, f.points);
                EXPECT_GT(f.maxBefore, 5 * kUm) << s.machine;
                EXPECT_LT(f.maxAfter, 0.1 * f.maxBefore) << s.machine << " L=" << L << " per=" << per;
            }
        }
        size_t present = 0;
        for (char p : all.present) present += p != 0;
        EXPECT_EQ(r.compensated.size() + r.notCompensated.size(), present) << s.machine;
    }
}

TEST(ControllerIsg, EveryIsoParameterIsClaimedAndFixedLinksNot) {
    const EmitResult r = emitSample(kSamples[1], deviations(kSamples[1]));
    EXPECT_TRUE(r.notCompensated.empty());  // every deviation of the table-table variant has an ISO name
    const MachineModel& m = machine("multitasking");
    const EmitResult t = emitSample(kSamples[0], deviations(kSamples[0]));
    // EX0C1 EZ0C1 EA0C1 sit on the spindle C1, behind B: constant component errors of B (P0/N0 stay nominal, or the
    // compensation's nominal model would carry them too).
    int behindB = 0;
    for (const Coverage& c : t.compensated) behindB += c.note.find("constant component errors of B") != std::string::npos;
    EXPECT_EQ(behindB, 3);
    EXPECT_EQ(t.compensated.size(), m.deviations.size());
    const std::string& csv = requireFile(t.files, "volcomp.csv", "test").content;
    EXPECT_NE(csv.find("\nB EXB EZB EAB\n"), std::string::npos);
}

TEST(ControllerIsg, CsvSyntaxReadIndependently) {
    for (const Sample& s : kSamples) {
        const MachineModel& m = machine(s.machine);
        const EmitResult r = emitSample(s, deviations(s));
        const OutputFile& csv = requireFile(r.files, "volcomp.csv", "test");
        // Blocks split on lone '#', '//' comments dropped, header then rows of as many numbers.
        std::istringstream in(csv.content);
        std::string line;
        std::vector<std::string> header;
        std::vector<std::vector<double>> rows;
        int blocks = 0;
        const auto closeBlock = [&] {
            if (header.empty()) return;
            ASSERT_FALSE(rows.empty());
            const std::string& arg = header[0];
            if (m.axisIndex(arg) >= 0) {
                for (size_t i = 1; i < rows.size(); ++i) ASSERT_GT(rows[i][0], rows[i - 1][0]);
                if (m.axisLink(m.axisIndex(arg)).modulo) {  // one turn, closing on itself
                    EXPECT_EQ(rows.front()[0], 0.0);
                    EXPECT_EQ(rows.back()[0], 360.0);
                    for (size_t c = 1; c < header.size(); ++c) EXPECT_EQ(rows.front()[c], rows.back()[c]) << header[c];
                }
            } else {
                EXPECT_EQ(rows.size(), 1u);
            }
            ++blocks;
            header.clear();
            rows.clear();
        };
        while (std::getline(in, line)) {
            if (line.rfind("//", 0) == 0) continue;
            if (line == "#") {
                closeBlock();
                continue;
            }
            std::istringstream ls(line);
            if (header.empty()) {
                for (std::string w; ls >> w;) header.push_back(w);
                continue;
            }
            std::vector<double> v;
            for (double x; ls >> x;) v.push_back(x);
            ASSERT_TRUE(ls.eof()) << line;
            ASSERT_EQ(v.size(), header.size()) << line;
            rows.push_back(v);
        }
        closeBlock();
        EXPECT_EQ(blocks, static_cast<int>(isg::parseIsgCsv(csv.content, "volcomp.csv").size()));
        EXPECT_GE(blocks, 1);
    }
}

TEST(ControllerIsg, GoldenFilesAreReproducedAndReadBack) {
    for (const Sample& s : kSamples) {
        const EmitResult r = emitSample(s, deviations(s));
        const std::vector<OutputFile> golden = compareWithGolden("isg", s.machine, r);
        const auto comp = backend("isg").apply(machine(s.machine), golden);
        const AxisVector q = AxisVector::Zero(machine(s.machine).axisCount());
        EXPECT_TRUE(comp->driveCommands(q).allFinite());
    }
}

TEST(ControllerIsg, ReadersNameFileAndLine) {
    using namespace isg;
    EXPECT_EQ(inputErrorLine([] { parseIsgCsv("X0C Y0C\n0.1\n", "v.csv"); }), 2);
    EXPECT_EQ(inputErrorLine([] { parseIsgCsv("// c\nX EXX EXX\n0 0 0\n", "v.csv"); }), 2);
    EXPECT_EQ(inputErrorLine([] { parseIsgCsv("X EXX\n0 zero\n", "v.csv"); }), 2);
    EXPECT_EQ(inputErrorLine([] { parseIsgCsv("X EXX\n0 1\n# x\n", "v.csv"); }), 3);
    EXPECT_EQ(inputErrorLine([] { parseIsgConfig("X 1\nchain XYZ\nfile_format[0] ETALON\n", "v.lis"); }), 3);
    EXPECT_EQ(inputErrorLine([] { parseIsgConfig("# c\nQ 1\n", "v.lis"); }), 2);
    const Sample& s = kSamples[1];
    EmitResult r = emitSample(s, deviations(s));
    // A parameter of an axis the chain does not have, and a name the model does not know.
    for (const char* bad : {" X0B", " Q0C"})
        for (OutputFile f : r.files) {
            if (f.name != "volcomp.csv") continue;
            const size_t line = f.content.find("\nP0X ");
            ASSERT_NE(line, std::string::npos);
            const size_t p = f.content.find(" X0C", line);
            ASSERT_NE(p, std::string::npos);
            f.content.replace(p, 4, bad);
            const int want = 1 + static_cast<int>(std::count(f.content.begin(), f.content.begin() + static_cast<long>(line) + 1, '\n'));
            EXPECT_EQ(inputErrorLine([&] { backend("isg").apply(machine(s.machine), {r.files[0], f}); }), want) << bad;
        }
    // Files of another machine.
    const EmitResult other = emitSample(kSamples[0], deviations(kSamples[0]));
    EXPECT_THROW(backend("isg").apply(machine(s.machine), other.files), InputError);
}

TEST(ControllerIsg, ANegateEntryFlipsTheCompensationAndVerifyFailsIt) {
    // P-VOLC-00009 `negate` (TF5280 "Modification of compensation values (optional)"): the control negates the computed
    // compensation of the Cartesian axes named; `set_to_zero` drops it. The files set neither and their header says
    // so; the apply model reads both. Oracle: the evaluation on the erroneous machine (the tool-tip error before and
    // after): with `negate XYZ` the correction points the wrong way and the error roughly doubles.
    const Sample& s = kSamples[1];
    const MachineModel& m = machine(s.machine);
    const DeviationSet d = deviations(s);
    const EmitResult r = emitSample(s, d);
    const DeviationSet claimed = claimedOnly(d, r);  // what the files claim to hold, as in CompensatesWhatItClaims…
    std::vector<OutputFile> files = r.files;
    OutputFile* lis = nullptr;
    for (OutputFile& f : files)
        if (f.name == "volcomp.lis") lis = &f;
    ASSERT_NE(lis, nullptr);
    EXPECT_NE(lis->content.find("sets neither 'negate' nor 'set_to_zero' (P-VOLC-00009"), std::string::npos) << lis->content;
    for (const isg::IsgConfig c = isg::parseIsgConfig(lis->content, "volcomp.lis"); const std::string* v : {&c.negate, &c.setToZero})
        EXPECT_TRUE(v->empty());
    const auto samples = workspaceSamples(m, 4);
    const auto figures = [&](const std::string& extra) {
        std::vector<OutputFile> changed = files;
        for (OutputFile& f : changed)
            if (f.name == "volcomp.lis") f.content += extra;
        return evaluateCompensation(m, claimed, *backend("isg").apply(m, changed), samples, 0.0);
    };
    const CompensationFigures plain = figures(""), negated = figures("negate XYZ\n");
    EXPECT_LT(plain.maxAfter, 0.1 * plain.maxBefore);
    EXPECT_GT(negated.maxAfter, 1.8 * plain.maxBefore);
    // Per axis: the correction of X alone flipped, of Z alone dropped.
    const AxisVector q = AxisVector::Zero(m.axisCount());
    const auto correction = [&](const std::string& extra) {
        std::vector<OutputFile> changed = files;
        for (OutputFile& f : changed)
            if (f.name == "volcomp.lis") f.content += extra;
        return AxisVector(backend("isg").apply(m, changed)->driveCommands(q) - q);
    };
    const AxisVector c0 = correction(""), cx = correction("negate X\n"), cz = correction("set_to_zero Z\n");
    const int X = m.requireAxis("X"), Y = m.requireAxis("Y"), Z = m.requireAxis("Z");
    ASSERT_GT(std::abs(c0[X]) + std::abs(c0[Z]), 1e-4);
    EXPECT_NEAR(cx[X], -c0[X], 1e-9);
    EXPECT_NEAR(cx[Y], c0[Y], 1e-9);
    EXPECT_NEAR(cz[Z], 0.0, 1e-9);
    EXPECT_NEAR(cz[X], c0[X], 1e-9);
    // Only the Cartesian axes, with file and line.
    EXPECT_EQ(inputErrorLine([] { isg::parseIsgConfig("X 1\nnegate XA\nchain XYZ\n", "v.lis"); }), 2);
}

TEST(ControllerIsg, ImplausibleValuesAreRefused) {
    const Sample& s = kSamples[1];
    DeviationSet d = deviations(s);
    const DeviationDef& exx = machine(s.machine).deviations[machine(s.machine).deviationIndex("EXX")];
    d.values[exx.offset + 3] = 25.0;  // 25 mm: a unit mistake
    EXPECT_THROW(emitSample(s, d), ModelError);
}


/// A machine from its two chains (axis letters with direction, bed outwards) for the chain-order cases of the documents.
MachineModel chainMachine(const std::string& name, const std::string& workpiece, const std::string& tool) {
    const auto links = [](const std::string& axes) {
        std::string x;
        for (char c : axes) {
            const bool rotary = c >= 'A' && c <= 'C';
            const int k = rotary ? c - 'A' : c - 'X';
            x += fmt::format(R"(<axis name="{}" type="{}" direction="{} {} {}" min="-200" max="200"/>)", c,
                             rotary ? "rotary" : "linear", int(k == 0), int(k == 1), int(k == 2));
        }
        return x;
    };
    test::ScratchDir dir("isg-chain");
    test::writeText(dir.file("m.xml"), fmt::format(R"(<machine name="{}"><workpiece>{}<fixed name="T"/></workpiece>
<tool direction="0 0 -1">{}<fixed name="S"/></tool></machine>)", name, links(workpiece), links(tool)));
    return readMachineXml(dir.file("m.xml"));
}

/// The `chain` and `workpiece_axes` lines of a compensation list, read without the backend's reader.
std::pair<std::string, int> chainLine(const std::string& lis) {
    std::istringstream in(lis);
    std::string line, chain;
    int wp = -1;
    while (std::getline(in, line)) {
        std::istringstream ls(line);
        std::string key, value;
        ls >> key >> value;
        if (key == "chain") chain = value;
        if (key == "workpiece_axes") wp = std::stoi(value);
    }
    return {chain, wp};
}

TEST(ControllerIsg, ChainRunsFromTheWorkpieceOverTheOriginToTheTool) {
    // Oracle: the documents' own examples. TF5240 "Example of an AC machine with cardanic table": rotary axes in the
    // table (C on A), linear axes on the tool side: "C, A, X, Y, Z". TF5280 "Cartesian pre-compensation": machine
    // XYZBC with rotary and swivel axis in the workpiece: "CBYXZ". P-VOLC-00007: "XYZCA ... a conventional CA machine"
    // (C and A in the head).
    struct Case {
        const char* name;
        const char* workpiece;
        const char* tool;
        const char* chain;
        int workpieceAxes;
    };
    for (const Case& c : {Case{"tf5240-ac-cardanic", "AC", "XYZ", "CAXYZ", 2}, Case{"tf5280-xyzbc", "BC", "YXZ", "CBYXZ", 2},
                          Case{"p-volc-00007-ca-head", "", "XYZCA", "XYZCA", 0}}) {
        const MachineModel m = chainMachine(c.name, c.workpiece, c.tool);
        const EmitResult r = backend("isg").emit({m, DeviationSet(m), "none", "2024-01-01"});
        EXPECT_EQ(chainLine(requireFile(r.files, "volcomp.lis", "test").content), std::make_pair(std::string(c.chain), c.workpieceAxes))
            << c.name;
        if (std::string(c.chain) == "CBYXZ") {
            // TF5280 "Tool length": N0 "is typically the direction of the last axis in the kinematic chain, i.e. [0, 0, -1]
            // for the example machine CBYXZ".
            const auto blocks = isg::parseIsgCsv(requireFile(r.files, "volcomp.csv", "test").content, "volcomp.csv");
            const auto& cols = blocks.at(0).columns;
            const auto at = [&](const char* n) { return blocks[0].rows[0][static_cast<size_t>(std::find(cols.begin(), cols.end(), n) - cols.begin())]; };
            EXPECT_EQ(Vec3(at("N0X"), at("N0Y"), at("N0Z")), Vec3(0, 0, -1));
        }
    }
    // The samples: table-table A/C (C on A, tool Y X Z), mill-turn (C work spindle, tool Z Y X B), tilting head.
    const std::map<std::string, std::pair<std::string, int>> want = {{"controllers-table-table-ac", {"CAYXZ", 2}},
                                                                     {"multitasking", {"CZYXB", 1}},
                                                                     {"controllers-tilting-head-b", {"XYZB", 0}}};
    for (const Sample& s : kSamples)
        EXPECT_EQ(chainLine(requireFile(emitSample(s, deviations(s)).files, "volcomp.lis", "test").content), want.at(s.machine)) << s.machine;
}

/// The ISG model read back from the files (isg_model.hpp, which never sees the description's chains) against the
/// description's own kinematics: the tool point seen from the workpiece agrees up to the workpiece frame at the
/// controller's zero, without errors and with them.
void expectModelIsTheMachine(const MachineModel& m, const DeviationSet& d, double tolerance) {
    const EmitResult r = backend("isg").emit({m, d, "x", "2024-01-01"});
    ASSERT_TRUE(r.notCompensated.empty()) << m.name;
    const isg::IsgConfig cfg = isg::parseIsgConfig(requireFile(r.files, "volcomp.lis", "test").content, "volcomp.lis");
    const std::string& csv = requireFile(r.files, "volcomp.csv", "test").content;
    const isg::IsgModel model(cfg, {{"volcomp.csv", isg::parseIsgCsv(csv, "volcomp.csv")}});
    const Kinematics nominal(m), actual(m, d);
    const Pose w0 = nominal.baseToWorkpiece(m.fromController(AxisVector::Zero(m.axisCount())));
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(0, 1);
    for (int n = 0; n < 200; ++n) {
        AxisVector q(m.axisCount());
        std::map<char, double> values;
        for (int a = 0; a < m.axisCount(); ++a) {
            const Link& l = m.axisLink(a);
            const double lo = std::max(l.min, -kPi), hi = std::min(l.max, kPi);
            q[a] = l.kind == AxisKind::Rotary ? lo + (hi - lo) * u(rng) : std::max(l.min, -300.0) + (std::min(l.max, 300.0) - std::max(l.min, -300.0)) * u(rng);
            const double p = q[a] - l.machineZero;
            values[m.axisNames[a][0]] = l.kind == AxisKind::Rotary ? p / kDeg : p;
        }
        for (double L : {0.0, 120.0}) {
            const Vec3 tip = nominal.toolPoint(L);
            EXPECT_LT((model.toolPoint(values, L, false) - w0 * nominal.toolPointInWorkpiece(q, tip)).norm(), 1e-9) << m.name;
            EXPECT_LT((model.toolPoint(values, L, true) - w0 * actual.toolPointInWorkpiece(q, tip)).norm(), tolerance) << m.name;
        }
    }
}

TEST(ControllerIsg, ModelReadFromTheFilesIsTheMachine) {
    // With errors the tables interpolate polynomial and Fourier component errors between their 181 records: 0.01 um.
    for (const Sample& s : kSamples) expectModelIsTheMachine(machine(s.machine), deviations(s), 1e-5);
    // Nominal offsets (C 50 mm below A, a turned table plate, a spindle 150 mm up) and every kind of component error.
    const MachineModel comp = readMachineXml(test::sourcePath("samples/machines/controllers-heidenhain-components.xml"));
    DeviationSet d = readDeviationCsv(test::sourcePath("samples/deviations/controllers-heidenhain-components.csv"), comp);
    d.values.segment(comp.deviations[comp.deviationIndex("EZC")].offset, comp.deviations[comp.deviationIndex("EZC")].size()).setZero();
    expectModelIsTheMachine(comp, d, 1e-5);
}

TEST(ControllerIsg, PositionsAreTheControllersMachineCoordinates) {
    const MachineModel& base = machine("controllers-table-table-ac");
    const MachineModel m = test::withMachineZero(base, {{"X", -250.0}, {"Z", 300.0}, {"C", 90.0}});
    const DeviationSet d = test::sameDeviations(deviations(kSamples[1]), m);
    expectModelIsTheMachine(m, d, 1e-5);
    const EmitResult r = backend("isg").emit({m, d, "x", "2024-01-01"});
    // Oracle: by hand. At machine coordinates 0 the tool reference point is at description X = -250, Z = 300.
    const auto blocks = isg::parseIsgCsv(requireFile(r.files, "volcomp.csv", "test").content, "volcomp.csv");
    const auto col = [&](const std::string& name) {
        const auto& c = blocks[0].columns;
        return blocks[0].rows[0][static_cast<size_t>(std::find(c.begin(), c.end(), name) - c.begin())];
    };
    EXPECT_NEAR(col("P0X"), -250.0, 1e-9);
    EXPECT_NEAR(col("P0Z"), 300.0, 1e-9);
    const CompensationFigures f = emitApplyEvaluate(backend("isg"), m, claimedOnly(d, r), workspaceSamples(m, 4), 100.0);
    EXPECT_LT(f.maxAfter, 0.1 * f.maxBefore);
}

}  // namespace
}  // namespace cnccomp::controllers
