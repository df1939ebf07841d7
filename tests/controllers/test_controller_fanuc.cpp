// fanuc-30i backend: golden files parsed back, emit → apply → residual volumetric error for the claimed errors,
// parameter-file grammar, rotary pitch tables summing to zero, limits, malformed files rejected with file:line.
#include <gtest/gtest.h>

#include <cctype>
#include <cmath>
#include <functional>
#include <sstream>

#include "cnccomp/error.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "controller_test_util.hpp"
#include "controllers/common/evaluate.hpp"
#include "controllers/fanuc/fanuc_backend.hpp"
#include "controllers/fanuc/parameter_file.hpp"
#include "controllers/fanuc/tcp_parameters.hpp"
#include "test_support.hpp"

namespace cnccomp::controllers {
using namespace cnccomp::controllers::common;
using namespace cnccomp::io;
namespace {

using test::sourcePath;

const Backend& fanuc30i() { return backend("fanuc-30i"); }

const MachineModel& pitchMachine() {
    static const MachineModel m = readMachineXml(sourcePath("samples/machines/controllers-fanuc-pitch.xml"));
    return m;
}

DeviationSet pitchTruth() {
    return readDeviationCsv(sourcePath("samples/deviations/controllers-fanuc-pitch.csv"), pitchMachine());
}

/// The deviations the backend lists as compensated, the others removed.
DeviationSet claimedOnly(const DeviationSet& d, const EmitResult& r) {
    DeviationSet c = d;
    for (const auto& nc : r.notCompensated) {
        const int i = c.machine().deviationIndex(nc.deviation);
        if (i < 0) continue;  // e.g. "EXX (constant part)"
        const auto& def = c.machine().deviations[i];
        for (int k = 0; k < def.size(); ++k) c.values[def.offset + k] = 0.0;
        c.present[i] = 0;
    }
    return c;
}

/// N<5 digits>Q<0|1>(P<v>|L<n>P<v>|(A<n>P<v>)+), <v> = [+-]digits[.digits]: checked character by character,
/// independently of the reader.
bool matchesGrammar(const std::string& l) {
    size_t i = 0;
    const auto digits = [&](size_t atLeast) {
        const size_t s = i;
        while (i < l.size() && std::isdigit(static_cast<unsigned char>(l[i]))) ++i;
        return i - s >= atLeast;
    };
    const auto value = [&] {
        if (i < l.size() && (l[i] == '+' || l[i] == '-')) ++i;
        if (!digits(1)) return false;
        if (i < l.size() && l[i] == '.') {
            ++i;
            return digits(1);
        }
        return true;
    };
    const auto letter = [&](char c) { return i < l.size() && l[i] == c ? (++i, true) : false; };
    if (!letter('N')) return false;
    const size_t n0 = i;
    if (!digits(5) || i - n0 != 5) return false;
    if (!letter('Q') || !(letter('0') || letter('1'))) return false;
    if (letter('P')) return value() && i == l.size();
    if (letter('L')) return digits(1) && letter('P') && value() && i == l.size();
    if (!letter('A')) return false;
    do {
        if (!digits(1) || !letter('P') || !value()) return false;
    } while (letter('A'));
    return i == l.size();
}

TEST(ControllerFanuc, RegisteredUnderItsName) { EXPECT_EQ(fanuc30i().name(), "fanuc-30i"); }

TEST(ControllerFanuc, GoldenFilesMultitaskingParseBack) {
    const MachineModel& m = test::multitasking();
    const DeviationSet d = readDeviationCsv(sourcePath("samples/deviations/multitasking-truth.csv"), m);
    test::checkGolden(fanuc30i(), m, d, "multitasking-truth.csv", "fanuc/multitasking");
}

TEST(ControllerFanuc, GoldenFilesPitchParseBack) {
    test::checkGolden(fanuc30i(), pitchMachine(), pitchTruth(), "controllers-fanuc-pitch.csv", "fanuc/pitch");
}

TEST(ControllerFanuc, GoldenFilesOtherSampleMachinesParseBack) {
    for (const char* name : {"tilting-head-b", "table-table-ac"}) {
        const MachineModel m = readMachineXml(sourcePath(std::string("samples/machines/") + name + ".xml"));
        test::checkGolden(fanuc30i(), m, test::patternedLocationErrors(m), "patterned", std::string("fanuc/") + name);
    }
}

// [MultiTasking]'s machine: the four pivot/offset errors are claimed; the nine angles are listed NOT compensated.
TEST(ControllerFanuc, MultitaskingPivotErrors) {
    const MachineModel& m = test::multitasking();
    const DeviationSet d = readDeviationCsv(sourcePath("samples/deviations/multitasking-truth.csv"), m);
    const EmitResult r = fanuc30i().emit({m, d, "multitasking-truth.csv", "2024-01-01"});
    EXPECT_EQ(r.compensated.size(), 4u);
    EXPECT_EQ(r.notCompensated.size(), 9u);
    const auto samples = test::nonSingularSamples(m, 4);
    const CompensationFigures f = test::evaluateBackend(fanuc30i(), m, claimedOnly(d, r), samples, 100.0);
    test::report("fanuc-30i multitasking (claimed: pivots)", f);
    EXPECT_GT(f.maxBefore, 0.015);
    EXPECT_LT(f.maxAfter, 0.1 * f.maxBefore);
    const CompensationFigures all = test::evaluateBackend(fanuc30i(), m, d, samples, 100.0);
    test::report("fanuc-30i multitasking (all 13, angles left)", all);
    EXPECT_LT(all.maxAfter, all.maxBefore);
}

TEST(ControllerFanuc, SampleMachinesRandomTranslationErrors) {
    for (const char* name : {"tilting-head-b", "table-table-ac"}) {
        const MachineModel m = readMachineXml(sourcePath(std::string("samples/machines/") + name + ".xml"));
        const DeviationSet d = test::randomLocationErrors(m, 31);
        const EmitResult r = fanuc30i().emit({m, d, "random", "2024-01-01"});
        const CompensationFigures f =
            test::evaluateBackend(fanuc30i(), m, claimedOnly(d, r), test::nonSingularSamples(m, 4), 100.0);
        test::report(std::string("fanuc-30i ") + name + " (claimed)", f);
        EXPECT_GT(f.maxBefore, 0.01) << name;
        EXPECT_LT(f.maxAfter, 0.1 * f.maxBefore) << name;
    }
}

TEST(ControllerFanuc, PivotAndPitchErrorsClaimedAreCompensated) {
    const MachineModel& m = pitchMachine();
    const DeviationSet d = pitchTruth();
    const EmitResult r = fanuc30i().emit({m, d, "controllers-fanuc-pitch.csv", "2024-01-01"});
    std::set<std::string> refused;
    for (const auto& c : r.notCompensated) refused.insert(c.deviation);
    EXPECT_EQ(refused, (std::set<std::string>{"EA0B", "EC0Y", "EYX", "EXX (rounded to 0.0001 mm)", "EYY (rounded to 0.0001 mm)",
                                              "EZZ (rounded to 0.0001 mm)", "EBB (rounded to 0.0001 deg)",
                                              "ECC (rounded to 0.0001 deg)"}));
    const auto samples = test::nonSingularSamples(m, 4, 300.0);
    const CompensationFigures f = test::evaluateBackend(fanuc30i(), m, claimedOnly(d, r), samples, 100.0);
    test::report("fanuc-30i pivots + pitch (claimed)", f);
    EXPECT_GT(f.maxBefore, 0.03);
    EXPECT_LT(f.maxAfter, 0.1 * f.maxBefore);
    const CompensationFigures all = test::evaluateBackend(fanuc30i(), m, d, samples, 100.0);
    test::report("fanuc-30i pivots + pitch (all, 3 left)", all);
}

// The TCP offsets read back are the pivot positions of the deviation set ([MultiTasking]: C axis line, spindle).
TEST(ControllerFanuc, TcpOffsetsAreThePivotPositions) {
    const MachineModel& m = pitchMachine();
    DeviationSet d(m);
    d.set("EX0C", -0.015);
    d.set("EY0C", 0.010);
    d.set("EX0S", 0.012);
    d.set("EZ0S", 0.015);
    d.set("EX0B", 0.007);
    const EmitResult r = fanuc30i().emit({m, d, "x", "2024-01-01"});
    const fanuc::ParameterFile f = fanuc::parseParameterFile(r.files[0].name, r.files[0].content);
    const fanuc::TcpParameters p = fanuc::tcpFromFile(m, f);
    EXPECT_EQ(p.type, 21);
    EXPECT_EQ(m.axisNames[p.rotary[0].axis], "B");
    EXPECT_EQ(m.axisNames[p.rotary[1].axis], "C");
    EXPECT_EQ(p.rotary[0].direction, 2);
    EXPECT_EQ(p.rotary[1].direction, 3);
    // Controlled point on the B axis (at X = 0.007): D -> E is from the tool reference point up to it.
    EXPECT_NEAR(p.toolOffset.x(), -0.012, 1e-12);
    EXPECT_NEAR(p.toolOffset.z(), 150.0 - 0.015, 1e-12);
    // The C axis line, seen from the controlled point; the workpiece datum on it.
    EXPECT_NEAR(p.tablePosition.x(), -0.015 - 0.007, 1e-12);
    EXPECT_NEAR(p.tablePosition.y(), 0.010, 1e-12);
    EXPECT_NEAR((p.workZero - p.tablePosition).norm(), 0.0, 1e-12);
}

TEST(ControllerFanuc, EveryLineMatchesTheParameterGrammar) {
    const EmitResult r = fanuc30i().emit({pitchMachine(), pitchTruth(), "x", "2024-01-01"});
    const std::string& text = r.files.at(0).content;
    std::istringstream in(text);
    std::string line;
    int state = 0, body = 0;
    while (std::getline(in, line)) {
        if (state == 0) {
            if (line == "%") state = 1;
            else EXPECT_TRUE(line.empty() || (line.front() == '(' && line.back() == ')')) << line;
            continue;
        }
        if (state == 2) {
            ADD_FAILURE() << "text after the closing %: " << line;
            continue;
        }
        if (line == "%") {
            state = 2;
            continue;
        }
        ++body;
        EXPECT_TRUE(matchesGrammar(line)) << line;
    }
    EXPECT_EQ(state, 2);
    EXPECT_GT(body, 100);
    // The checker itself refuses what the grammar refuses.
    for (const char* bad : {"N1968Q1L1P21", "N19680Q2L1P21", "N19680Q1L1P", "N19680Q1L1P2.", "N19680Q1L1P2e3",
                            "N01220Q1A1P1A2", "N19680Q1P1 ", "(comment)", "N10000Q0P-"})
        EXPECT_FALSE(matchesGrammar(bad)) << bad;
    EXPECT_TRUE(matchesGrammar("N01220Q1A1P-0.0150A2P+0.0100A3P0"));
    EXPECT_EQ(text.find('\r'), std::string::npos);
}

TEST(ControllerFanuc, RotaryPitchTableSumsToZeroOverARevolution) {
    const MachineModel& m = pitchMachine();
    const EmitResult r = fanuc30i().emit({m, pitchTruth(), "x", "2024-01-01"});
    const fanuc::ParameterFile f = fanuc::parseParameterFile(r.files[0].name, r.files[0].content);
    const auto tables = fanuc::pitchFromFile(m, f);
    ASSERT_EQ(tables.size(), 5u);  // X Y Z B C
    const int c = m.requireAxis("C");
    for (const auto& t : tables) {
        if (t.axis != c) {
            EXPECT_FALSE(t.rotaryType);
            EXPECT_DOUBLE_EQ(t.correction(0.0, 1e-4), 0.0);  // zero at the reference position
            continue;
        }
        EXPECT_TRUE(t.rotaryType);
        EXPECT_EQ(t.reference, t.negative);
        EXPECT_DOUBLE_EQ((t.positive - t.negative) * t.interval, 360.0);
        long sum = 0;
        for (size_t k = 1; k < t.data.size(); ++k) sum += t.data[k];
        EXPECT_EQ(sum, 0);
        // ECC = 8" sin c - 3" sin 2c; the correction is -ECC (within half a detection unit per point).
        for (double deg : {17.0, 95.0, 250.0, 250.0 - 720.0}) {
            const double q = deg * kDeg;
            const double ecc = (8 * std::sin(q) - 3 * std::sin(2 * q)) / 3600.0;
            EXPECT_NEAR(t.correction(deg, 1e-4), -ecc, 1.5e-4) << deg;
        }
    }
}

TEST(ControllerFanuc, ConstantPartOfAPositioningErrorIsReported) {
    const MachineModel& m = pitchMachine();
    DeviationSet d(m);
    const auto& ecc = m.deviations[m.deviationIndex("ECC")];
    d.values[ecc.offset] = 5 * kArcsec;  // cos c: 5" at the reference position
    d.present[m.deviationIndex("ECC")] = 1;
    const EmitResult r = fanuc30i().emit({m, d, "x", "2024-01-01"});
    ASSERT_EQ(r.notCompensated.size(), 2u);
    EXPECT_EQ(r.notCompensated[0].deviation, "ECC (rounded to 0.0001 deg)");
    EXPECT_NE(r.notCompensated[0].note.find("up to 0.18 arcsec"), std::string::npos) << r.notCompensated[0].note;
    EXPECT_EQ(r.notCompensated[1].deviation, "ECC (constant part)");
    EXPECT_NE(r.notCompensated[1].note.find("5.000 arcsec"), std::string::npos) << r.notCompensated[1].note;
    EXPECT_NE(r.files[0].content.find("(  ECC [constant part]"), std::string::npos);
}

TEST(ControllerFanuc, ConstantPartOfALinearPositioningErrorGoesIntoTheTcpOffsets) {
    // A linear axis off by a constant carries everything behind it by that much: the TCP offsets and 1220 hold it
    // (the pitch table is zero at the reference position). Oracle: the exact erroneous kinematics at the drive commands
    // (evaluate.hpp). table-table-bc-offsets: X's reference position (machine 0) is the command 50 mm, where the EXX
    // table reads -4 + 2.5 * 100 / 150 = -2.333 um.
    const MachineModel m = readMachineXml(sourcePath("samples/machines/table-table-bc-offsets.xml"));
    const DeviationSet truth = readDeviationCsv(sourcePath("samples/deviations/table-table-bc-offsets-truth.csv"), m);
    DeviationSet d(m);
    const int exx = m.deviationIndex("EXX");
    const auto& def = m.deviations[static_cast<size_t>(exx)];
    d.values.segment(def.offset, def.size()) = truth.values.segment(def.offset, def.size());
    d.present[static_cast<size_t>(exx)] = 1;
    const EmitResult r = fanuc30i().emit({m, d, "x", "2024-01-01"});
    ASSERT_EQ(r.notCompensated.size(), 1u);  // only the rounding to the detection unit, no constant part
    EXPECT_EQ(r.notCompensated[0].deviation, "EXX (rounded to 0.0001 mm)");
    ASSERT_EQ(r.compensated.size(), 1u);
    EXPECT_NE(r.compensated[0].note.find("1220"), std::string::npos) << r.compensated[0].note;
    const CompensationFigures f = emitApplyEvaluate(fanuc30i(), m, d, test::nonSingularSamples(m, 4), 50.0);
    EXPECT_GT(f.maxBefore, 2.3 * kUm);
    EXPECT_LT(f.maxAfter, 0.06 * kUm);  // the pitch data's detection unit (0.1 um) rounds each absolute value
}

TEST(ControllerFanuc, LimitsAreReportedAsModelErrors) {
    const EmitRequest req{pitchMachine(), pitchTruth(), "x", "2024-01-01"};
    fanuc::PitchOptions few;
    few.maxPoints = 200;
    try {
        fanuc::emitFiles(req, few);
        FAIL() << "expected ModelError";
    } catch (const ModelError& e) {
        EXPECT_NE(std::string(e.what()).find("the control holds 200"), std::string::npos) << e.what();
    }
    fanuc::PitchOptions narrow;
    narrow.maxData = 1;
    narrow.maxMagnification = 1;
    EXPECT_THROW(fanuc::emitFiles(req, narrow), ModelError);
    fanuc::PitchOptions coarse;
    coarse.maxIntervals = 16;
    const EmitResult r = fanuc::emitFiles(req, coarse);
    for (const auto& t : fanuc::pitchFromFile(pitchMachine(), fanuc::parseParameterFile("p", r.files[0].content)))
        EXPECT_LE(t.positive - t.negative, 16);
    // Three rotary axes: no 30i machine type.
    MachineModel three;
    three.name = "three-rotary";
    Link a, b, c, s;
    a.name = "A", a.kind = AxisKind::Rotary, a.direction = Vec3::UnitX();
    b.name = "B", b.kind = AxisKind::Rotary, b.direction = Vec3::UnitY();
    c.name = "C", c.kind = AxisKind::Rotary, c.direction = Vec3::UnitZ();
    s.name = "S";
    three.workpiece.links = {a, c};
    three.tool.links = {b, s};
    three.finalize();
    EXPECT_THROW(fanuc30i().emit({three, DeviationSet(three), "x", "2024-01-01"}), ModelError);
    // Linear axis moving the table: the 30i TCP parameters describe linear axes that move the tool.
    const MachineModel tableX = test::tableXMachine();
    EXPECT_THROW(fanuc30i().emit({tableX, test::tableXErrors(tableX), "x", "2024-01-01"}), ModelError);
}

TEST(ControllerFanuc, MalformedFilesAreRejectedWithFileAndLine) {
    const MachineModel& m = pitchMachine();
    const EmitResult r = fanuc30i().emit({m, pitchTruth(), "x", "2024-01-01"});
    const std::string text = r.files[0].content;
    const auto apply = [&](const std::string& content) {
        return test::inputErrorOf([&] { fanuc30i().apply(m, {{fanuc::kParameterFile, content}}); });
    };
    const int typeLine = test::lineOf(text, "N19680Q1L1P");
    EXPECT_EQ(apply(test::replaceLine(text, typeLine, "N19680Q1L1P5")),
              fmt::format("CNCCOMP.PRM:{}: parameter 19680: machine type 5 is not 0, 2, 12 or 21", typeLine));
    EXPECT_EQ(apply(test::replaceLine(text, typeLine, "N1968Q1L1P21")),
              fmt::format("CNCCOMP.PRM:{}: 'N1968Q1L1P21' does not match N<5 digits>Q<0|1>(P<v>|L<n>P<v>|(A<n>P<v>)+): the "
                          "parameter number has 5 digits",
                          typeLine));
    EXPECT_NE(apply(test::replaceLine(text, typeLine, "N19680Q1L1P2.1e1")).find("does not match"), std::string::npos);
    EXPECT_NE(apply(test::replaceLine(text, typeLine, "G01 X10")).find(fmt::format("CNCCOMP.PRM:{}:", typeLine)), std::string::npos);
    // A parameter twice.
    const int pos = test::lineOf(text, "N19700Q1L1P");
    std::string twice = test::replaceLine(text, pos, text.substr(text.find("N19700"), text.find('\n', text.find("N19700")) - text.find("N19700")) +
                                                         "\n" + text.substr(text.find("N19700"), text.find('\n', text.find("N19700")) - text.find("N19700")));
    EXPECT_EQ(apply(twice), fmt::format("CNCCOMP.PRM:{}: parameter 19700 given twice", pos + 1));
    // Missing closing %, comment between the % lines, text before the opening %.
    EXPECT_NE(apply(text.substr(0, text.rfind("%"))).find("missing the closing %"), std::string::npos);
    EXPECT_NE(apply("hello\n" + text).find("CNCCOMP.PRM:1: before the opening % only (comment) lines are allowed"), std::string::npos);
    // The rotary table's data no longer summing to zero.
    const fanuc::ParameterFile pf = fanuc::parseParameterFile("p", text);
    int cFirst = -1;
    for (const auto& t : fanuc::pitchFromFile(m, pf))
        if (t.rotaryType) cFirst = t.negative;
    ASSERT_GE(cFirst, 0);
    const int dataLine = test::lineOf(text, fmt::format("N{}Q0P", 10000 + cFirst + 5));
    const std::string broken = test::replaceLine(text, dataLine, fmt::format("N{}Q0P77", 10000 + cFirst + 5));
    const std::string msg = apply(broken);
    EXPECT_NE(msg.find("not 0"), std::string::npos) << msg;
    EXPECT_EQ(msg.rfind("CNCCOMP.PRM:", 0), 0u) << msg;
    // A missing data point, an unknown parameter, the wrong file.
    std::string gap = text;
    const size_t at = gap.find(fmt::format("\nN{}Q0P", 10000 + cFirst + 5));
    gap.erase(at, gap.find('\n', at + 1) - at);
    EXPECT_NE(apply(gap).find(fmt::format("parameter {} is missing", 10000 + cFirst + 5)), std::string::npos) << apply(gap);
    EXPECT_EQ(apply(test::replaceLine(text, typeLine, "N01005Q1A1P1")),
              fmt::format("CNCCOMP.PRM:{}: parameter 1005 is not one cnccomp writes or models", typeLine));
    EXPECT_EQ(test::inputErrorOf([&] { fanuc30i().apply(m, {{"OTHER.TXT", text}}); }), "OTHER.TXT: not a fanuc-30i file (expected CNCCOMP.PRM)");
}

}  // namespace
}  // namespace cnccomp::controllers

namespace cnccomp::controllers {
namespace {

/// The printed compensation values of the parameter manual's example 1 (Series 0i-PB parameter manual B-63980EN/01,
/// parameters 3620-3624, p.100): points 33..49, reference point 40, interval 50 mm.
const std::vector<long> kExample1 = {+2, +1, +1, -2, 0, -1, 0, -1, +2, +1, 0, -1, -1, -2, 0, +1, +2};

/// Absolute compensation at the section ends -400, -350, ..., +450 mm, summed by hand from kExample1 as the manual
/// explains it (0 at the reference position; point k's value is output across the section that ends at point k).
const std::vector<double> kExample1Absolute = {0, 2, 3, 4, 2, 2, 1, 1, 0, 2, 3, 3, 2, 1, -1, -1, 0, 2};

/// The number a parameter line carries after `prefix` (e.g. "N19700Q1L1P"), read from the text without the reader.
double rawParameter(const std::string& text, const std::string& prefix) {
    const size_t p = text.find("\n" + prefix);
    if (p == std::string::npos) return std::nan("");
    const size_t start = p + 1 + prefix.size();
    return std::stod(text.substr(start, text.find_first_of("AN\n", start) - start));
}

TEST(ControllerFanuc, PitchModelSumsTheManualsExample1) {
    // Oracle: the parameter manual's own example and its rule for the absolute compensation.
    fanuc::PitchTable t;
    t.reference = 40;
    t.negative = 33;
    t.positive = 49;
    t.interval = 50.0;
    t.data = kExample1;
    for (size_t j = 0; j < kExample1Absolute.size(); ++j) {
        const double x = -400.0 + 50.0 * static_cast<double>(j);
        EXPECT_NEAR(t.correction(x, 1.0), kExample1Absolute[j], 1e-12) << x;
    }
    EXPECT_NEAR(t.correction(-425.0, 1.0), 0.0, 1e-12);  // ends held
    EXPECT_NEAR(t.correction(-275.0, 1.0), 3.5, 1e-12);  // halfway between +4 (-250) and +3 (-300)
}

TEST(ControllerFanuc, PitchWriterReproducesTheManualsExample1) {
    // A linear axis of the example's stroke whose positioning error is the negated absolute compensation of the
    // example: the writer must number the points as the manual (reference 40 -> 33..49, here from 0) and write its values.
    test::ScratchDir dir("fanuc-example-1");
    std::string nodes;
    for (int j = 0; j < 18; ++j) nodes += fmt::format("{} ", -400 + 50 * j);
    test::writeText(dir.file("m.xml"), fmt::format(R"(<machine name="fanuc-example-1">
<workpiece><fixed name="T"/></workpiece>
<tool direction="0 0 -1">
<axis name="X" type="linear" direction="1 0 0" min="-400" max="450"/>
<axis name="Y" type="linear" direction="0 1 0" min="-100" max="100"/>
<axis name="Z" type="linear" direction="0 0 1" min="-100" max="100"/>
<fixed name="S"/>
</tool>
<deviations><component name="EXX" link="X" component="x" basis="table" nodes="{}"/></deviations>
</machine>
)", nodes));
    const MachineModel m = readMachineXml(dir.file("m.xml"));
    DeviationSet d(m);
    const int exx = m.deviationIndex("EXX");
    for (int j = 0; j < 18; ++j) d.values[m.deviations[exx].offset + j] = -kExample1Absolute[j] * 1e-4;  // IS-C units
    d.present[exx] = 1;
    fanuc::PitchOptions o;
    o.maxIntervals = 17;
    const EmitResult r = fanuc::emitFiles({m, d, "example", "2024-01-01"}, o);
    const std::string& text = r.files.at(0).content;
    const int ref = static_cast<int>(rawParameter(text, "N03620Q1A1P"));
    const int neg = static_cast<int>(rawParameter(text, "N03621Q1A1P"));
    const int pos = static_cast<int>(rawParameter(text, "N03622Q1A1P"));
    EXPECT_EQ(ref - neg, 40 - 33);
    EXPECT_EQ(pos - neg, 49 - 33);
    EXPECT_DOUBLE_EQ(rawParameter(text, "N03624Q1A1P"), 50.0);
    EXPECT_DOUBLE_EQ(rawParameter(text, "N03623Q1A1P"), 1.0);
    for (int k = neg; k <= pos; ++k)
        EXPECT_EQ(rawParameter(text, fmt::format("N{}Q0P", 10000 + k)), kExample1[k - neg]) << "point " << k;
}

TEST(ControllerFanuc, RotaryReferencePointHoldsTheLastPointsValue) {
    // B-63980EN p.100 example 2: 45 deg interval, 3621 = 3620, 3622 = 3620 + 8, the values of 3620+1..3622 sum to
    // zero and "for compensation position 3620, set the same compensation value as for 3622".
    const MachineModel& m = pitchMachine();
    fanuc::PitchOptions o;
    o.maxIntervals = 8;
    const EmitResult r = fanuc::emitFiles({m, pitchTruth(), "x", "2024-01-01"}, o);
    const std::string& text = r.files.at(0).content;
    const int c = controllerAxisNumber(m, m.requireAxis("C"));
    const auto param = [&](int n) { return static_cast<int>(rawParameter(text, fmt::format("N0{}Q1A", n))); };
    (void)param;
    const fanuc::ParameterFile f = fanuc::parseParameterFile("p", text);
    const int ref = static_cast<int>(fanuc::required(f, 3620, c)), neg = static_cast<int>(fanuc::required(f, 3621, c)),
              pos = static_cast<int>(fanuc::required(f, 3622, c));
    EXPECT_EQ(neg, ref);
    EXPECT_EQ(pos, ref + 8);
    EXPECT_DOUBLE_EQ(fanuc::required(f, 3624, c), 45.0);
    long sum = 0;
    for (int k = ref + 1; k <= pos; ++k) sum += static_cast<long>(rawParameter(text, fmt::format("N{}Q0P", 10000 + k)));
    EXPECT_EQ(sum, 0);
    const double atRef = rawParameter(text, fmt::format("N{}Q0P", 10000 + ref));
    const double atLast = rawParameter(text, fmt::format("N{}Q0P", 10000 + pos));
    EXPECT_NE(atLast, 0.0);  // ECC = 8" sin c - 3" sin 2c changes by -2.66" over 315..360 deg
    EXPECT_EQ(atRef, atLast);
    // A file that breaks the rule is refused at the reference point's line.
    const int refLine = test::lineOf(text, fmt::format("N{}Q0P", 10000 + ref));
    const std::string broken = test::replaceLine(text, refLine, fmt::format("N{}Q0P0", 10000 + ref));
    const std::string msg = test::inputErrorOf([&] { fanuc30i().apply(m, {{fanuc::kParameterFile, broken}}); });
    EXPECT_EQ(msg.rfind(fmt::format("CNCCOMP.PRM:{}:", refLine), 0), 0u) << msg;
    EXPECT_NE(msg.find("must equal the value at the last point"), std::string::npos) << msg;
}

TEST(ControllerFanuc, AbsoluteValuesAreInTheControllersMachineCoordinates) {
    // The same machine, its controller counting X from -250 mm, Z from +400 mm and C from 90 deg of the description.
    const MachineModel& base = pitchMachine();
    const MachineModel m = test::withMachineZero(base, {{"X", -250.0}, {"Z", 400.0}, {"C", 90.0}});
    DeviationSet d(m);
    d.set("EX0C", 0.015);
    d.set("EY0C", -0.010);
    d.set("EX0B", 0.007);
    d.set("EZ0B", -0.004);
    const EmitResult r = fanuc30i().emit({m, d, "x", "2024-01-01"});
    const std::string& text = r.files.at(0).content;
    // Oracle: by hand. At machine coordinates 0 the controlled point (on the B axis line) is at description
    // X = -250 + EX0B, Z = 400 + EZ0B; the C axis line at X = EX0C, Y = EY0C, Z = 0 (A-79348E: 19700-19702 are the
    // machine coordinates of a point on the table's rotary axis, rotary axes at 0).
    EXPECT_NEAR(rawParameter(text, "N19700Q1L1P"), 0.015 + 250.0 - 0.007, 1e-4);
    EXPECT_NEAR(rawParameter(text, "N19701Q1L1P"), -0.010, 1e-4);
    EXPECT_NEAR(rawParameter(text, "N19702Q1L1P"), -400.0 + 0.004, 1e-4);
    EXPECT_NE(text.find("X -250 mm, Z 400 mm, C 90 deg"), std::string::npos);
    // The TCP on those numbers compensates the physical machine.
    const auto samples = test::nonSingularSamples(m, 4);
    const CompensationFigures f = test::evaluateBackend(fanuc30i(), m, d, samples, 100.0);
    test::report("fanuc-30i machine-zero (pivots)", f);
    EXPECT_GT(f.maxBefore, 0.01);
    EXPECT_LT(f.maxAfter, 0.1 * f.maxBefore);
    // The same file read as if the description's commands were the machine coordinates is far off: the numbers are
    // not in the description's frame.
    const DeviationSet d0 = test::sameDeviations(d, base);
    const auto wrong = fanuc30i().apply(base, r.files);
    const CompensationFigures g = evaluateCompensation(base, d0, *wrong, test::nonSingularSamples(base, 4), 100.0);
    EXPECT_GT(g.maxAfter, 1.0);
}

TEST(ControllerFanuc, PitchTablesStartAtTheMachineZero) {
    const MachineModel m = test::withMachineZero(pitchMachine(), {{"X", -250.0}, {"C", 180.0}});
    DeviationSet d = test::sameDeviations(pitchTruth(), m);
    // EXX = a1 x + a2 x^2 with a1 = 250 a2 and ECC = 8" sin c - 3" sin 2c vanish at the machine zeros, where a pitch
    // table is zero (a constant part there is reported NOT compensated; ControllerFanuc.ConstantPart... covers it).
    const DeviationDef& exx = m.deviations[m.deviationIndex("EXX")];
    d.values[exx.offset] = 250.0 * d.values[exx.offset + 1];
    const EmitResult r = fanuc30i().emit({m, d, "x", "2024-01-01"});
    const auto tables = fanuc::pitchFromFile(m, fanuc::parseParameterFile("p", r.files.at(0).content));
    const auto e = [&](double q) { return exx.basis.evaluate(q, d.values.data() + exx.offset, false); };
    for (const auto& t : tables) {
        if (m.axisNames[t.axis] != "X") continue;
        // Oracle: EXX (a polynomial of the description's command) at command = machine position - 250 mm; the
        // reference position (zero correction) is the machine zero, not the description's X = 0.
        for (double p : {-400.0, -130.0, 0.0, 250.0, 610.0, 900.0}) {
            const double want = -(e(p - 250.0) - e(-250.0));
            EXPECT_NEAR(t.correction(p, 1e-4), want, 1.5e-4) << p;
        }
    }
    const CompensationFigures f = test::evaluateBackend(fanuc30i(), m, claimedOnly(d, r), test::nonSingularSamples(m, 4, 300.0), 100.0);
    test::report("fanuc-30i machine-zero (pivots + pitch)", f);
    EXPECT_LT(f.maxAfter, 0.1 * f.maxBefore);
}

}  // namespace
}  // namespace cnccomp::controllers
