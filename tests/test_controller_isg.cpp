// ISG / TF5280 backend: emit → apply on the erroneous machine (≥ 90 % less tip error for what it claims, with the
// tool length the controller applies), ISG_CSV syntax read back independently, goldens, readers, limits.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <sstream>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "controllers/common/evaluate.hpp"
#include "controllers/isg/isg_files.hpp"
#include "test_controller_common_support.hpp"

namespace cnccomp::controllers {
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
    // EX0C1 EZ0C1 EA0C1 sit on the spindle C1: tool zero P0/N0.
    int toolZero = 0;
    for (const Coverage& c : t.compensated) toolZero += c.note.find("tool zero") != std::string::npos;
    EXPECT_EQ(toolZero, 3);
    EXPECT_EQ(t.compensated.size(), m.deviations.size());
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
    // A parameter the machine does not have.
    for (OutputFile& f : r.files)
        if (f.name == "volcomp.csv") {
            const size_t line = f.content.find("\nP0X ");
            ASSERT_NE(line, std::string::npos);
            const size_t p = f.content.find(" X0C", line);
            ASSERT_NE(p, std::string::npos);
            f.content.replace(p, 4, " Z0C");
        }
    EXPECT_THROW(backend("isg").apply(machine(s.machine), r.files), InputError);
    // Files of another machine.
    const EmitResult other = emitSample(kSamples[0], deviations(kSamples[0]));
    EXPECT_THROW(backend("isg").apply(machine(s.machine), other.files), InputError);
}

TEST(ControllerIsg, ImplausibleValuesAreRefused) {
    const Sample& s = kSamples[1];
    DeviationSet d = deviations(s);
    const DeviationDef& exx = machine(s.machine).deviations[machine(s.machine).deviationIndex("EXX")];
    d.values[exx.offset + 3] = 25.0;  // 25 mm: a unit mistake
    EXPECT_THROW(emitSample(s, d), ModelError);
}

}  // namespace
}  // namespace cnccomp::controllers
