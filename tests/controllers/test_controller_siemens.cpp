// siemens-840d backend: golden files parsed back, emit → apply → residual volumetric error, CEC/EEC format
// rules (MIN/MAX/STEP vs point count, modulo tables closing), limits, malformed files rejected with file:line.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <functional>
#include <cstdio>
#include <sstream>

#include "cnccomp/error.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "controllers/common/evaluate.hpp"
#include "controllers/siemens/compensation_tables.hpp"
#include "controllers/siemens/kinematic_chain.hpp"
#include "controllers/siemens/siemens_backend.hpp"
#include "controller_test_util.hpp"
#include "test_support.hpp"

namespace cnccomp::controllers {
using namespace cnccomp::controllers::common;
using namespace cnccomp::io;
namespace {

using test::sourcePath;

const Backend& siemens() { return backend("siemens-840d"); }

const MachineModel& componentsMachine() {
    static const MachineModel m = readMachineXml(sourcePath("samples/machines/controllers-siemens-components.xml"));
    return m;
}

TEST(ControllerSiemens, RegisteredUnderItsName) {
    EXPECT_EQ(siemens().name(), "siemens-840d");
    EXPECT_FALSE(siemens().description().empty());
}

TEST(ControllerSiemens, GoldenFilesMultitaskingParseBack) {
    const MachineModel& m = test::multitasking();
    const DeviationSet d = readDeviationCsv(sourcePath("samples/deviations/multitasking-truth.csv"), m);
    test::checkGolden(siemens(), m, d, "multitasking-truth.csv", "siemens/multitasking");
}

TEST(ControllerSiemens, GoldenFilesComponentsParseBack) {
    const MachineModel& m = componentsMachine();
    const DeviationSet d = readDeviationCsv(sourcePath("samples/deviations/controllers-siemens-components.csv"), m);
    test::checkGolden(siemens(), m, d, "controllers-siemens-components.csv", "siemens/components");
}

TEST(ControllerSiemens, GoldenFilesOtherSampleMachinesParseBack) {
    for (const char* name : {"tilting-head-b", "table-table-ac"}) {
        const MachineModel m = readMachineXml(sourcePath(std::string("samples/machines/") + name + ".xml"));
        test::checkGolden(siemens(), m, test::patternedLocationErrors(m), "patterned", std::string("siemens/") + name);
    }
}

// All 13 location errors of [MultiTasking]'s machine are claimed: squareness by CEC lines (+ the head orientation
// folded into the chain), everything else by the kinematic chain.
TEST(ControllerSiemens, MultitaskingTruthResidualBelowTenPercent) {
    const MachineModel& m = test::multitasking();
    const DeviationSet d = readDeviationCsv(sourcePath("samples/deviations/multitasking-truth.csv"), m);
    const EmitResult r = siemens().emit({m, d, "multitasking-truth.csv", "2024-01-01"});
    EXPECT_EQ(r.compensated.size(), 13u);
    EXPECT_TRUE(r.notCompensated.empty());
    const CompensationFigures f = test::evaluateBackend(siemens(), m, d, test::nonSingularSamples(m, 4), 100.0);
    test::report("siemens-840d multitasking truth", f);
    EXPECT_GT(f.maxBefore, 0.02);
    EXPECT_LT(f.maxAfter, 0.1 * f.maxBefore);
    EXPECT_LT(f.maxAfter, 2e-4);  // second-order terms of the CEC straight lines only
}

// Linear axes on both chains: the table X's squareness and straightness trim the column's axes (and back).
TEST(ControllerSiemens, TableSideLinearAxis) {
    const MachineModel m = test::tableXMachine();
    const DeviationSet d = test::tableXErrors(m);
    const EmitResult r = siemens().emit({m, d, "table-x", "2024-01-01"});
    EXPECT_TRUE(r.notCompensated.empty());
    const CompensationFigures f = test::evaluateBackend(siemens(), m, d, test::nonSingularSamples(m, 4), 100.0);
    test::report("siemens-840d table-x (table-side X)", f);
    EXPECT_GT(f.maxBefore, 0.02);
    EXPECT_LT(f.maxAfter, 0.1 * f.maxBefore);
}

TEST(ControllerSiemens, SampleMachinesRandomLocationErrors) {
    for (const char* name : {"tilting-head-b", "table-table-ac"}) {
        const MachineModel m = readMachineXml(sourcePath(std::string("samples/machines/") + name + ".xml"));
        const DeviationSet d = test::randomLocationErrors(m, 11);
        const CompensationFigures f = test::evaluateBackend(siemens(), m, d, test::nonSingularSamples(m, 4), 100.0);
        test::report(std::string("siemens-840d ") + name, f);
        EXPECT_GT(f.maxBefore, 0.01) << name;
        EXPECT_LT(f.maxAfter, 0.1 * f.maxBefore) << name;
    }
}

}  // namespace
}  // namespace cnccomp::controllers

namespace cnccomp::controllers {
namespace {

DeviationSet withoutDeviation(DeviationSet d, const std::string& name) {
    const int i = d.require(name);
    const auto& def = d.machine().deviations[i];
    for (int k = 0; k < def.size(); ++k) d.values[def.offset + k] = 0.0;
    d.present[i] = 0;
    return d;
}

// Component errors: positioning (EEC), straightness and radial motion (CEC) are claimed; the roll EAX is not.
TEST(ControllerSiemens, ComponentErrorsClaimedAreCompensated) {
    const MachineModel& m = componentsMachine();
    const DeviationSet d = readDeviationCsv(sourcePath("samples/deviations/controllers-siemens-components.csv"), m);
    const EmitResult r = siemens().emit({m, d, "controllers-siemens-components.csv", "2024-01-01"});
    ASSERT_EQ(r.notCompensated.size(), 1u);
    EXPECT_EQ(r.notCompensated[0].deviation, "EAX");
    const DeviationSet claimed = withoutDeviation(d, "EAX");
    const auto samples = test::nonSingularSamples(m, 4, 300.0);
    const CompensationFigures f = test::evaluateBackend(siemens(), m, claimed, samples, 100.0);
    test::report("siemens-840d components (claimed)", f);
    EXPECT_GT(f.maxBefore, 0.02);
    EXPECT_LT(f.maxAfter, 0.1 * f.maxBefore);
    const CompensationFigures all = test::evaluateBackend(siemens(), m, d, samples, 100.0);
    test::report("siemens-840d components (all, EAX left)", all);
}

}  // namespace
}  // namespace cnccomp::controllers

namespace cnccomp::controllers {
namespace {

const OutputFile& file(const EmitResult& r, const std::string& name) {
    for (const auto& f : r.files)
        if (f.name == name) return f;
    throw std::runtime_error("no file " + name);
}

EmitResult componentsEmit() {
    const MachineModel& m = componentsMachine();
    const DeviationSet d = readDeviationCsv(sourcePath("samples/deviations/controllers-siemens-components.csv"), m);
    return siemens().emit({m, d, "controllers-siemens-components.csv", "2024-01-01"});
}

// Every table's points are numbered 0..N-1 with N = (MAX-MIN)/STEP + 1, counted from the text itself.
TEST(ControllerSiemens, CecMinMaxStepMatchThePointCount) {
    const EmitResult r = componentsEmit();
    const std::string& text = file(r, siemens::kCecFile).content;
    std::map<int, int> count;
    std::map<int, double> step, mn, mx;
    std::istringstream in(text);
    std::string line;
    while (std::getline(in, line)) {
        int t = -1, n = -1;
        double v = 0;
        char field[8] = {};
        if (std::sscanf(line.c_str(), "$AN_CEC[%d,%d]=%lf", &t, &n, &v) == 3) {
            EXPECT_EQ(n, count[t]) << "points of table " << t << " are numbered in order";
            ++count[t];
        } else if (std::sscanf(line.c_str(), "$AN_CEC_%4[A-Z][%d]=%lf", field, &t, &v) == 3) {
            const std::string f(field);
            if (f == "STEP") step[t] = v;
            if (f == "MIN") mn[t] = v;
            if (f == "MAX") mx[t] = v;
        }
    }
    ASSERT_GE(count.size(), 5u);  // X->Y, X->Z, Y->X or Y->Z, Y->Z, C->X, C->Y, B->X, B->Z ...
    for (const auto& [t, n] : count) {
        ASSERT_TRUE(step.count(t) && mn.count(t) && mx.count(t)) << t;
        const double intervals = (mx[t] - mn[t]) / step[t];
        EXPECT_NEAR(intervals, std::round(intervals), 1e-9) << t;
        EXPECT_EQ(n, static_cast<int>(std::lround(intervals)) + 1) << "table " << t;
        EXPECT_LE(n, siemens::Options{}.cecMaxPoints);
    }
}

// Squareness is a straight line through zero: output = slope x input, slope = the squareness angle.
TEST(ControllerSiemens, SquarenessIsAStraightLine) {
    const MachineModel& m = test::multitasking();
    DeviationSet d(m);
    d.setLinkValue("EC0Y", 10 * kArcsec);  // the X slide turned by +gamma (ISO EC0Y = -gamma)
    const EmitResult r = siemens().emit({m, d, "EC0Y only", "2024-01-01"});
    const auto tables = siemens::parseCec(m, siemens::kCecFile, file(r, siemens::kCecFile).content);
    ASSERT_EQ(tables.size(), 1u);
    const auto& t = tables[0];
    EXPECT_EQ(m.axisNames[t.input], "X");
    EXPECT_EQ(m.axisNames[t.output], "Y");
    // X slide rotated by +gamma about Z moves +gamma*x in Y: the trim is -gamma*x (rounded to 1 nm).
    for (size_t n = 0; n < t.table.values.size(); ++n) {
        const double x = t.table.min + t.table.step * n;
        EXPECT_NEAR(t.table.values[n], -std::tan(10 * kArcsec) * x, 6e-7) << x;
    }
    EXPECT_NEAR(t.table.at(0.0), 0.0, 1e-12);
}

// Modulo tables (the C axis) span one revolution and close on themselves.
TEST(ControllerSiemens, ModuloTablesCloseOnThemselves) {
    const MachineModel& m = componentsMachine();
    const EmitResult r = componentsEmit();
    const auto cec = siemens::parseCec(m, siemens::kCecFile, file(r, siemens::kCecFile).content);
    const auto eec = siemens::parseEec(m, siemens::kEecFile, file(r, siemens::kEecFile).content);
    const int c = m.requireAxis("C");
    int modulo = 0;
    for (const auto& t : cec)
        if (t.input == c) {
            ++modulo;
            EXPECT_TRUE(t.table.modulo);
            EXPECT_DOUBLE_EQ(t.table.min, 0.0);
            EXPECT_DOUBLE_EQ(t.table.max(), 360.0);
            EXPECT_DOUBLE_EQ(t.table.values.front(), t.table.values.back());
        }
    for (const auto& t : eec)
        if (t.axis == c) {
            ++modulo;
            EXPECT_TRUE(t.table.modulo);
            EXPECT_DOUBLE_EQ(t.table.max() - t.table.min, 360.0);
            EXPECT_DOUBLE_EQ(t.table.values.front(), t.table.values.back());
            // ECC = 6" cos c - 4" sin c + 3" cos 2c + 2" sin 2c, in degrees.
            const double q = 30 * kDeg;
            const double ecc = (6 * std::cos(q) - 4 * std::sin(q) + 3 * std::cos(2 * q) + 2 * std::sin(2 * q)) / 3600.0;
            EXPECT_NEAR(t.table.at(30.0), ecc, 1e-8);
            EXPECT_NEAR(t.table.at(390.0), ecc, 1e-8);   // wraps
            EXPECT_NEAR(t.table.at(-330.0), ecc, 1e-8);
        }
    EXPECT_EQ(modulo, 3);  // C->X, C->Y (radial motion) and the EEC of C
}

TEST(ControllerSiemens, LimitsAreReportedAsModelErrors) {
    const MachineModel& m = componentsMachine();
    const DeviationSet d = readDeviationCsv(sourcePath("samples/deviations/controllers-siemens-components.csv"), m);
    const EmitRequest req{m, d, "x", "2024-01-01"};
    siemens::Options few;
    few.cecMaxPoints = 50;
    try {
        siemens::emitFiles(req, few);
        FAIL() << "expected ModelError";
    } catch (const ModelError& e) {
        EXPECT_NE(std::string(e.what()).find("MM_CEC_MAX_POINTS = 50"), std::string::npos) << e.what();
    }
    siemens::Options tables;
    tables.cecMaxTables = 2;
    EXPECT_THROW(siemens::emitFiles(req, tables), ModelError);
    siemens::Options chain;
    chain.chainMaxElements = 4;
    EXPECT_THROW(siemens::emitFiles(req, chain), ModelError);
    siemens::Options coarse;
    coarse.tablePoints = 11;  // fewer, coarser points still fit and still compensate
    const EmitResult r = siemens::emitFiles(req, coarse);
    for (const auto& t : siemens::parseCec(m, siemens::kCecFile, file(r, siemens::kCecFile).content))
        EXPECT_LE(t.table.values.size(), 11u);
}

TEST(ControllerSiemens, LinearAxisOnARotaryAxisIsRefused) {
    MachineModel m;
    m.name = "rotary-carries-linear";
    Link c;
    c.name = "C";
    c.kind = AxisKind::Rotary;
    Link x;
    x.name = "X";
    x.kind = AxisKind::Linear;
    x.direction = Vec3::UnitX();
    x.min = -100;
    x.max = 100;
    Link s;
    s.name = "S";
    m.tool.links = {c, x, s};
    m.finalize();
    const DeviationSet d(m);
    EXPECT_THROW(siemens().emit({m, d, "x", "2024-01-01"}), ModelError);
}

// Broken files are refused with the file name and the line.
TEST(ControllerSiemens, MalformedFilesAreRejectedWithFileAndLine) {
    const MachineModel& m = componentsMachine();
    const EmitResult r = componentsEmit();
    const auto withFile = [&](const std::string& name, const std::string& content) {
        std::vector<OutputFile> files = r.files;
        for (auto& f : files)
            if (f.name == name) f.content = content;
        return test::inputErrorOf([&] { siemens().apply(m, files); });
    };
    const std::string cec = file(r, siemens::kCecFile).content;
    const std::string eec = file(r, siemens::kEecFile).content;
    const std::string chain = file(r, siemens::kChainFile).content;

    const int stepLine = test::lineOf(cec, "$AN_CEC_STEP[0]=");
    EXPECT_EQ(withFile(siemens::kCecFile, test::replaceLine(cec, stepLine, "$AN_CEC_STEP[0]=abc")),
              fmt::format("NC_CEC.INI:{}: 'abc' is not a number", stepLine));
    EXPECT_EQ(withFile(siemens::kCecFile, test::replaceLine(cec, stepLine, "G01 X10")),
              fmt::format("NC_CEC.INI:{}: expected $VARIABLE[...]=value, CHANDATA(n), a ';' comment or M17; got 'G01 X10'", stepLine));
    // One point fewer than (MAX-MIN)/STEP+1.
    const int p3 = test::lineOf(cec, "$AN_CEC[0,3]=");
    const std::string missing = withFile(siemens::kCecFile, test::replaceLine(cec, p3, "; removed"));
    EXPECT_NE(missing.find("NC_CEC.INI:"), std::string::npos);
    EXPECT_NE(missing.find("points expected"), std::string::npos) << missing;
    // STEP that does not divide MAX-MIN.
    const std::string badStep = withFile(siemens::kCecFile, test::replaceLine(cec, stepLine, "$AN_CEC_STEP[0]=3.3"));
    EXPECT_NE(badStep.find("not a whole number of intervals"), std::string::npos) << badStep;
    // Unknown axis.
    const int inLine = test::lineOf(cec, "$AN_CEC_INPUT_AXIS[0]=");
    EXPECT_EQ(withFile(siemens::kCecFile, test::replaceLine(cec, inLine, "$AN_CEC_INPUT_AXIS[0]=(AX9)")),
              fmt::format("NC_CEC.INI:{}: machine 'controllers-siemens-components' has no axis AX9", inLine));
    // No M17.
    const std::string noEnd = withFile(siemens::kCecFile, cec.substr(0, cec.rfind("M17")));
    EXPECT_NE(noEnd.find("missing M17"), std::string::npos) << noEnd;
    // A modulo table whose last point differs from the first.
    const int c = m.requireAxis("C");
    const std::string axC = siemens::axisName(m, c);
    size_t lastIndex = 0;
    for (const auto& t : siemens::parseEec(m, siemens::kEecFile, eec))
        if (t.axis == c) lastIndex = t.table.values.size() - 1;
    ASSERT_GT(lastIndex, 0u);
    const int last = test::lineOf(eec, fmt::format("$AA_ENC_COMP[0,{},{}]=", lastIndex, axC));
    ASSERT_GT(last, 0);
    const std::string open =
        withFile(siemens::kEecFile, test::replaceLine(eec, last, fmt::format("$AA_ENC_COMP[0,{},{}]=0.5", lastIndex, axC)));
    EXPECT_EQ(open.rfind(fmt::format("AX_EEC.INI:{}:", last), 0), 0u) << open;
    EXPECT_NE(open.find("does not close on itself"), std::string::npos) << open;
    // Chain: a broken link and a wrong identifier.
    const int next = test::lineOf(chain, "$NK_NEXT[1]=");
    EXPECT_EQ(withFile(siemens::kChainFile, test::replaceLine(chain, next, "$NK_NEXT[1]=\"NOWHERE\"")),
              fmt::format("CNCCOMP_KINCHAIN.SPF:{}: $NK_NEXT of 'T_Z' names no element ('NOWHERE')", test::lineOf(chain, "$NK_NAME[1]=")));
    EXPECT_EQ(withFile(siemens::kChainFile, test::replaceLine(chain, 1, "%_N_OTHER_SPF")),
              "CNCCOMP_KINCHAIN.SPF:1: file identifier is %_N_OTHER_SPF, expected %_N_CNCCOMP_KINCHAIN_SPF");
    const int type = test::lineOf(chain, "$NK_TYPE[1]=");
    EXPECT_EQ(withFile(siemens::kChainFile, test::replaceLine(chain, type, "$NK_TYPE[1]=\"AXIS_ROT\"")),
              fmt::format("CNCCOMP_KINCHAIN.SPF:{}: AX3 is axis Z of machine 'controllers-siemens-components', which is linear",
                          test::lineOf(chain, "$NK_NAME[1]=")));
    // The root: no machine data naming it, or naming an element that does not exist.
    const int md = test::lineOf(chain, "$MN_ROOT_KIN_ELEM_NAME=");
    ASSERT_GT(md, 0);
    EXPECT_EQ(withFile(siemens::kChainFile, test::replaceLine(chain, md, "; removed")),
              "CNCCOMP_KINCHAIN.SPF: no $MN_ROOT_KIN_ELEM_NAME naming the chain root");
    EXPECT_EQ(withFile(siemens::kChainFile, test::replaceLine(chain, md, "$MN_ROOT_KIN_ELEM_NAME=\"BASE\"")),
              fmt::format("CNCCOMP_KINCHAIN.SPF:{}: $MN_ROOT_KIN_ELEM_NAME names 'BASE', which no $NK_NAME has", md));
    // Missing chain file; unknown file.
    std::vector<OutputFile> noChain;
    for (const auto& f : r.files)
        if (f.name != siemens::kChainFile) noChain.push_back(f);
    EXPECT_EQ(test::inputErrorOf([&] { siemens().apply(m, noChain); }),
              "CNCCOMP_KINCHAIN.SPF: missing: the kinematic chain file is needed for TRAORI");
    std::vector<OutputFile> extra = r.files;
    extra.push_back({"NOTES.TXT", "hello"});
    EXPECT_NE(test::inputErrorOf([&] { siemens().apply(m, extra); }).find("NOTES.TXT: not a siemens-840d file"), std::string::npos);
    // Binary content.
    EXPECT_NE(withFile(siemens::kCecFile, std::string("%_N_NC_CEC_INI\n\x01\x02\n")).find("binary content"), std::string::npos);
}


TEST(ControllerSiemens, ChainStartsAtTheRootTheMachineDataNames) {
    // Oracle: the archive layout of K7/K12 (element 0 "ROOT", found through MD16800 $MN_ROOT_KIN_ELEM_NAME; its
    // $NK_NEXT starts one subchain, $NK_PARALLEL the other), read line by line without the backend's reader.
    const MachineModel& m = test::multitasking();
    const DeviationSet d = readDeviationCsv(sourcePath("samples/deviations/multitasking-truth.csv"), m);
    const EmitResult r = siemens().emit({m, d, "x", "2024-01-01"});
    std::string chain;
    for (const auto& f : r.files)
        if (f.name == siemens::kChainFile) chain = f.content;
    std::istringstream in(chain);
    std::vector<std::string> assignments;
    for (std::string line; std::getline(in, line);)
        if (line.rfind("$", 0) == 0) assignments.push_back(line);
    ASSERT_GE(assignments.size(), 6u);
    EXPECT_EQ(assignments[0], "$MN_ROOT_KIN_ELEM_NAME=\"ROOT\"");
    EXPECT_EQ(assignments[1], "$NK_NAME[0]=\"ROOT\"");
    EXPECT_EQ(assignments[2], "$NK_TYPE[0]=\"OFFSET\"");
    std::string next, parallel;
    for (const std::string& a : assignments) {
        if (a.rfind("$NK_NEXT[0]=", 0) == 0) next = a.substr(12);
        if (a.rfind("$NK_PARALLEL[0]=", 0) == 0) parallel = a.substr(16);
    }
    EXPECT_EQ(next, "\"T_Z\"");       // the tool subchain: Z first from the bed
    EXPECT_EQ(parallel.rfind("\"P_C", 0), 0u) << parallel;  // the part subchain: the C work spindle (its offset first)
}

TEST(ControllerSiemens, ChainAndTablesAreInTheMachineCoordinates) {
    const MachineModel& base = componentsMachine();
    const MachineModel m = test::withMachineZero(base, {{"X", -250.0}, {"Z", 400.0}, {"B", 30.0}, {"C", 90.0}});
    const DeviationSet d = test::sameDeviations(
        readDeviationCsv(sourcePath("samples/deviations/controllers-siemens-components.csv"), base), m);
    const EmitResult r = siemens().emit({m, d, "x", "2024-01-01"});
    // Oracle: the positioning error EXX (a polynomial of the description's command) at the EEC table's positions, which
    // are machine positions: command = position - 250 mm.
    std::string eecText;
    for (const auto& f : r.files)
        if (f.name == siemens::kEecFile) eecText = f.content;
    const DeviationDef& exx = m.deviations[m.deviationIndex("EXX")];
    const int x = m.requireAxis("X");
    bool seen = false;
    for (const auto& t : siemens::parseEec(m, siemens::kEecFile, eecText)) {
        if (t.axis != x) continue;
        seen = true;
        for (double p : {-450.0, -100.0, 0.0, 333.0, 900.0})
            EXPECT_NEAR(t.table.at(p), exx.basis.evaluate(p - 250.0, d.values.data() + exx.offset, false), 2e-6) << p;
    }
    EXPECT_TRUE(seen);
    // TRAORI on the chain in machine coordinates, CEC and EEC at machine positions: the physical machine is compensated.
    const EmitResult claimed = siemens().emit({m, d, "x", "2024-01-01"});
    DeviationSet c = d;
    for (const auto& nc : claimed.notCompensated) {
        const int i = m.deviationIndex(nc.deviation);
        c.values.segment(m.deviations[i].offset, m.deviations[i].size()).setZero();
        c.present[i] = 0;
    }
    const CompensationFigures f = test::evaluateBackend(siemens(), m, c, test::nonSingularSamples(m, 4), 100.0);
    test::report("siemens-840d machine-zero (claimed)", f);
    EXPECT_LT(f.maxAfter, 0.1 * f.maxBefore);
    // Read as if the description's commands were the machine coordinates, the same files are far off.
    const DeviationSet c0 = test::sameDeviations(c, base);
    const CompensationFigures g = evaluateCompensation(base, c0, *siemens().apply(base, r.files), test::nonSingularSamples(base, 4), 100.0);
    EXPECT_GT(g.maxAfter, 0.5);
}


TEST(ControllerSiemens, RotConstTurnsAboutItsDirectionAsK7Prints) {
    // K7 (840D sl function manual special functions 01/2015, 6FC5397-2BP40-5BA2) p.202: the 9th element's direction
    // vector is (1; 0; 0) turned by 90 deg in the X/Y plane and 10 deg in the Y/Z plane, (cos90 cos10, sin90 cos10,
    // sin10) = (0.0, 0.985, 0.174), and "the output coordinate system ... arises from the input coordinate system,
    // rotated through the angle specified in $NK_A_OFF around the direction vector". A chain with such an element
    // after the slides of a three-axis machine, read back:
    test::ScratchDir dir("k7");
    test::writeText(dir.file("m.xml"), R"(<machine name="k7"><workpiece><fixed name="T"/></workpiece><tool direction="0 0 -1">
<axis name="X" type="linear" direction="1 0 0" min="-100" max="100"/><axis name="Y" type="linear" direction="0 1 0" min="-100" max="100"/>
<axis name="Z" type="linear" direction="0 0 1" min="-100" max="100"/></tool></machine>)");
    const MachineModel m = readMachineXml(dir.file("m.xml"));
    const double c = std::cos(90 * kDeg) * std::cos(10 * kDeg), sy = std::sin(90 * kDeg) * std::cos(10 * kDeg), sz = std::sin(10 * kDeg);
    std::string f = "%_N_CNCCOMP_KINCHAIN_SPF\n$MN_ROOT_KIN_ELEM_NAME=\"ROOT\"\n"
                    "$NK_NAME[0]=\"ROOT\"\n$NK_TYPE[0]=\"OFFSET\"\n$NK_OFF_DIR[0,0]=0\n$NK_OFF_DIR[0,1]=0\n$NK_OFF_DIR[0,2]=0\n"
                    "$NK_NEXT[0]=\"X\"\n$NK_PARALLEL[0]=\"P\"\n";
    const char* axes[3] = {"X", "Y", "Z"};
    for (int k = 0; k < 3; ++k)
        f += fmt::format("$NK_NAME[{0}]=\"{1}\"\n$NK_TYPE[{0}]=\"AXIS_LIN\"\n$NK_AXIS[{0}]=\"AX{0}\"\n$NK_OFF_DIR[{0},0]={2}\n"
                         "$NK_OFF_DIR[{0},1]={3}\n$NK_OFF_DIR[{0},2]={4}\n$NK_NEXT[{0}]=\"{5}\"\n",
                         k + 1, axes[k], int(k == 0), int(k == 1), int(k == 2), k < 2 ? axes[k + 1] : "NINTH");
    f += fmt::format("$NK_NAME[4]=\"NINTH\"\n$NK_TYPE[4]=\"ROT_CONST\"\n$NK_OFF_DIR[4,0]={:.15f}\n$NK_OFF_DIR[4,1]={:.15f}\n"
                     "$NK_OFF_DIR[4,2]={:.15f}\n$NK_A_OFF[4]=30\n$NK_NEXT[4]=\"\"\n",
                     c, sy, sz);
    f += "$NK_NAME[5]=\"P\"\n$NK_TYPE[5]=\"OFFSET\"\n$NK_OFF_DIR[5,0]=0\n$NK_OFF_DIR[5,1]=0\n$NK_OFF_DIR[5,2]=0\n$NK_NEXT[5]=\"\"\n"
         "$NT_NAME[1]=\"K7\"\n$NT_T_CHAIN_LAST_ELEM[1]=\"NINTH\"\n$NT_P_CHAIN_LAST_ELEM[1]=\"P\"\nM17\n";
    const siemens::ParsedChain pc = siemens::parseKinematicChain(m, "K7.SPF", f);
    ASSERT_EQ(pc.tool.size(), 5u);  // ROOT, X, Y, Z, the ninth element
    const ChainElement& e = pc.tool.back();
    ASSERT_EQ(e.type, ChainElement::Type::Constant);
    const Vec3 u(0.0, 0.985, 0.174);  // the manual's rounded components
    EXPECT_LT((e.pose.linear() * u.normalized() - u.normalized()).norm(), 2e-3);  // the direction stays
    const Vec3 w = u.unitOrthogonal();
    EXPECT_NEAR(std::acos(std::clamp((e.pose.linear() * w).dot(w), -1.0, 1.0)) / kDeg, 30.0, 1e-9);  // by $NK_A_OFF
    EXPECT_LT(((e.pose.linear() * w).cross(w)).dot(Vec3(c, sy, sz)), 0.0);  // right-handed: w turns towards u x w
}

}  // namespace
}  // namespace cnccomp::controllers
