// heidenhain-tnc backend: golden files parsed back, emit → apply → residual volumetric error, row limits,
// Trans rows beside their MachAxis, .COM tables (modulo tables closing), malformed files rejected with file:line.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <sstream>

#include "cnccomp/error.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "controller_test_util.hpp"
#include "controllers/common/evaluate.hpp"
#include "controllers/heidenhain/kinematics_table.hpp"
#include "controllers/heidenhain/tnc_table.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "app/verify.hpp"
#include "test_support.hpp"

namespace cnccomp::controllers {
using namespace cnccomp::controllers::common;
using namespace cnccomp::io;
using namespace cnccomp::measurement;
namespace {

using test::sourcePath;

const Backend& tnc() { return backend("heidenhain-tnc"); }

const MachineModel& componentsMachine() {
    static const MachineModel m = readMachineXml(sourcePath("samples/machines/controllers-heidenhain-components.xml"));
    return m;
}

DeviationSet componentsTruth() {
    return readDeviationCsv(sourcePath("samples/deviations/controllers-heidenhain-components.csv"), componentsMachine());
}

DeviationSet without(DeviationSet d, const std::string& name) {
    const int i = d.require(name);
    const auto& def = d.machine().deviations[i];
    for (int k = 0; k < def.size(); ++k) d.values[def.offset + k] = 0.0;
    d.present[i] = 0;
    return d;
}

const OutputFile& file(const EmitResult& r, const std::string& name) {
    for (const auto& f : r.files)
        if (f.name == name) return f;
    throw std::runtime_error("no file " + name);
}

TEST(ControllerHeidenhain, RegisteredUnderItsName) { EXPECT_EQ(tnc().name(), "heidenhain-tnc"); }

TEST(ControllerHeidenhain, GoldenFilesMultitaskingParseBack) {
    const MachineModel& m = test::multitasking();
    const DeviationSet d = readDeviationCsv(sourcePath("samples/deviations/multitasking-truth.csv"), m);
    test::checkGolden(tnc(), m, d, "multitasking-truth.csv", "heidenhain/multitasking");
}

TEST(ControllerHeidenhain, GoldenFilesComponentsParseBack) {
    test::checkGolden(tnc(), componentsMachine(), componentsTruth(), "controllers-heidenhain-components.csv",
                      "heidenhain/components");
}

TEST(ControllerHeidenhain, GoldenFilesOtherSampleMachinesParseBack) {
    for (const char* name : {"tilting-head-b", "table-table-ac"}) {
        const MachineModel m = readMachineXml(sourcePath(std::string("samples/machines/") + name + ".xml"));
        test::checkGolden(tnc(), m, test::patternedLocationErrors(m), "patterned", std::string("heidenhain/") + name);
    }
}

TEST(ControllerHeidenhain, MultitaskingTruthResidualBelowTenPercent) {
    const MachineModel& m = test::multitasking();
    const DeviationSet d = readDeviationCsv(sourcePath("samples/deviations/multitasking-truth.csv"), m);
    const EmitResult r = tnc().emit({m, d, "multitasking-truth.csv", "2024-01-01"});
    EXPECT_EQ(r.compensated.size(), 13u);
    EXPECT_TRUE(r.notCompensated.empty());
    const CompensationFigures f = test::evaluateBackend(tnc(), m, d, test::nonSingularSamples(m, 4), 100.0);
    test::report("heidenhain-tnc multitasking truth", f);
    EXPECT_GT(f.maxBefore, 0.02);
    EXPECT_LT(f.maxAfter, 0.1 * f.maxBefore);
    EXPECT_LT(f.maxAfter, 1e-5);  // the rows describe the erroneous chain exactly (rounded to 1e-9 mm / 1e-10 deg)
}

// Linear axes on both chains: the table X's squareness and straightness trim the column's axes (and back).
TEST(ControllerHeidenhain, TableSideLinearAxis) {
    const MachineModel m = test::tableXMachine();
    const DeviationSet d = test::tableXErrors(m);
    const EmitResult r = tnc().emit({m, d, "table-x", "2024-01-01"});
    EXPECT_TRUE(r.notCompensated.empty());
    const CompensationFigures f = test::evaluateBackend(tnc(), m, d, test::nonSingularSamples(m, 4), 100.0);
    test::report("heidenhain-tnc table-x (table-side X)", f);
    EXPECT_GT(f.maxBefore, 0.02);
    EXPECT_LT(f.maxAfter, 0.1 * f.maxBefore);
}

TEST(ControllerHeidenhain, SampleMachinesRandomLocationErrors) {
    for (const char* name : {"tilting-head-b", "table-table-ac"}) {
        const MachineModel m = readMachineXml(sourcePath(std::string("samples/machines/") + name + ".xml"));
        const DeviationSet d = test::randomLocationErrors(m, 23);
        const CompensationFigures f = test::evaluateBackend(tnc(), m, d, test::nonSingularSamples(m, 4), 100.0);
        test::report(std::string("heidenhain-tnc ") + name, f);
        EXPECT_GT(f.maxBefore, 0.01) << name;
        EXPECT_LT(f.maxAfter, 0.1 * f.maxBefore) << name;
    }
}

// KinematicsComp takes all six components of every axis; only the non-periodic EZC on the modulo C is refused.
TEST(ControllerHeidenhain, ComponentErrorsClaimedAreCompensated) {
    const MachineModel& m = componentsMachine();
    const DeviationSet d = componentsTruth();
    const EmitResult r = tnc().emit({m, d, "controllers-heidenhain-components.csv", "2024-01-01"});
    ASSERT_EQ(r.notCompensated.size(), 1u);
    EXPECT_EQ(r.notCompensated[0].deviation, "EZC");
    EXPECT_NE(r.notCompensated[0].note.find("close on itself"), std::string::npos);
    const auto samples = test::nonSingularSamples(m, 4);
    const CompensationFigures f = test::evaluateBackend(tnc(), m, without(d, "EZC"), samples, 100.0);
    test::report("heidenhain-tnc components (claimed)", f);
    EXPECT_GT(f.maxBefore, 0.03);
    EXPECT_LT(f.maxAfter, 0.1 * f.maxBefore);
    const CompensationFigures all = test::evaluateBackend(tnc(), m, d, samples, 100.0);
    test::report("heidenhain-tnc components (all, EZC left)", all);
}

// The C axis' location errors sit right before its MachAxis row (table side, base → table) with their ISO
// values; the B head's come right after its MachAxis row inverted (tool side is walked from the tool).
TEST(ControllerHeidenhain, LocationErrorsAreTransRowsBesideTheirMachAxis) {
    const MachineModel& m = test::multitasking();
    DeviationSet d(m);
    d.set("EX0C", 0.015);
    d.set("EY0C", -0.010);
    d.set("EB0B", 20 * kArcsec);
    const EmitResult r = tnc().emit({m, d, "x", "2024-01-01"});
    ASSERT_EQ(r.files.size(), 1u);
    const heidenhain::TncTable t = heidenhain::parseTncTable(r.files[0].name, r.files[0].content, {"KEY", "AXIS", "COORD", "DOC"});
    const int key = t.column("KEY"), axis = t.column("AXIS"), coord = t.column("COORD"), doc = t.column("DOC");
    int machC = -1, machB = -1, base = -1;
    for (size_t i = 0; i < t.rows.size(); ++i) {
        if (t.cell(i, key) == "MachAxis" && t.cell(i, axis) == "C") machC = static_cast<int>(i);
        if (t.cell(i, key) == "MachAxis" && t.cell(i, axis) == "B") machB = static_cast<int>(i);
        if (t.cell(i, key) == "MachBase") base = static_cast<int>(i);
    }
    ASSERT_GT(machC, base);
    ASSERT_LT(machB, base);
    EXPECT_EQ(t.cell(machC - 2, axis), "X");
    EXPECT_DOUBLE_EQ(std::stod(t.cell(machC - 2, coord)), 0.015);
    EXPECT_EQ(t.cell(machC - 1, axis), "Y");
    EXPECT_DOUBLE_EQ(std::stod(t.cell(machC - 1, coord)), -0.010);
    EXPECT_NE(t.cell(machC - 1, doc).find("EY0C"), std::string::npos);
    EXPECT_EQ(t.cell(machB + 1, key), "Trans");
    EXPECT_EQ(t.cell(machB + 1, axis), "B");
    EXPECT_NEAR(std::stod(t.cell(machB + 1, coord)), -20.0 / 3600.0, 1e-10);
    EXPECT_NE(t.cell(machB + 1, doc).find("inv:EB0B"), std::string::npos);
}

TEST(ControllerHeidenhain, ComTablesAndModuloClosure) {
    const MachineModel& m = componentsMachine();
    const EmitResult r = tnc().emit({m, componentsTruth(), "x", "2024-01-01"});
    // X.COM holds EXX..ECX in C1..C6 at EZX's own nodes? No: the columns share one AXISPOS set, so a grid.
    const auto x = heidenhain::parseTncTable("X.COM", file(r, "X.COM").content, {"NR", "AXISPOS", "C1", "C2", "C3", "C4", "C5", "C6"});
    EXPECT_LE(x.rows.size(), 256u);
    // EZX on the tool side (X carries the tool): the column holds -EZX; at X = 250 the table node is 4 um.
    const int pos = x.column("AXISPOS"), c3 = x.column("C3");
    bool found = false;
    for (size_t i = 0; i < x.rows.size(); ++i)
        if (std::stod(x.cell(i, pos)) == 250.0) {
            EXPECT_NEAR(std::stod(x.cell(i, c3)), -0.004, 1e-12);
            found = true;
        }
    EXPECT_TRUE(found);
    const auto c = heidenhain::parseTncTable("C.COM", file(r, "C.COM").content, {"NR", "AXISPOS"});
    ASSERT_GE(c.rows.size(), 3u);
    const int cp = c.column("AXISPOS");
    EXPECT_DOUBLE_EQ(std::stod(c.cell(0, cp)) + 360.0, std::stod(c.cell(c.rows.size() - 1, cp)));
    for (int k = 1; k <= 6; ++k) {
        const int col = c.column("C" + std::to_string(k));
        if (col < 0) continue;
        EXPECT_EQ(c.cell(0, col), c.cell(c.rows.size() - 1, col)) << "C" << k;
    }
    EXPECT_LT(c.column("C3"), 0);  // EZC is not there
}

TEST(ControllerHeidenhain, LimitsAreReportedAsModelErrors) {
    const EmitRequest req{componentsMachine(), componentsTruth(), "x", "2024-01-01"};
    heidenhain::Options rows;
    rows.maxTransformRows = 20;
    try {
        heidenhain::emitFiles(req, rows);
        FAIL() << "expected ModelError";
    } catch (const ModelError& e) {
        EXPECT_NE(std::string(e.what()).find("the TNC takes 20"), std::string::npos) << e.what();
    }
    heidenhain::Options entries;
    entries.maxCompEntries = 5;
    EXPECT_THROW(heidenhain::emitFiles(req, entries), ModelError);
    heidenhain::Options small;
    small.maxCompRows = 20;  // the grids get coarser but stay within the limit
    const EmitResult r = heidenhain::emitFiles(req, small);
    for (const auto& f : r.files)
        if (f.name.ends_with(".COM")) {
            EXPECT_LE(heidenhain::parseTncTable(f.name, f.content, {"NR"}).rows.size(), 20u);
        }
}

TEST(ControllerHeidenhain, AxisThatDoesNotMoveAlongItsLetterIsRefused) {
    MachineModel m;
    m.name = "odd";
    Link b;
    b.name = "B";
    b.kind = AxisKind::Rotary;
    b.direction = Vec3::UnitZ();  // a TNC B axis turns about Y
    Link s;
    s.name = "S";
    m.tool.links = {b, s};
    m.finalize();
    EXPECT_THROW(tnc().emit({m, DeviationSet(m), "x", "2024-01-01"}), ModelError);
}

TEST(ControllerHeidenhain, MalformedFilesAreRejectedWithFileAndLine) {
    const MachineModel& m = componentsMachine();
    const EmitResult r = tnc().emit({m, componentsTruth(), "x", "2024-01-01"});
    const std::string kinName = "CONTROLLERS_HEIDENHAIN_COMPONENTS.TAB";
    const std::string kin = file(r, kinName).content;
    const std::string com = file(r, "C.COM").content;
    const auto withFile = [&](const std::string& name, const std::string& content) {
        std::vector<OutputFile> files = r.files;
        for (auto& f : files)
            if (f.name == name) f.content = content;
        return test::inputErrorOf([&] { tnc().apply(m, files); });
    };
    const auto row = [&](const std::string& text, const std::string& nr) { return test::lineOf(text, "\n" + nr + " ") + 1; };
    // Row 3 numbered 7.
    const int l3 = row(kin, "3");
    std::string bad = kin;
    bad.replace(bad.find("\n3 ") + 1, 1, "7");
    EXPECT_EQ(withFile(kinName, bad), fmt::format("{}:{}: NR '7': expected 3", kinName, l3));
    // A COORD that is not a number.
    const int transLine = test::lineOf(kin, " Trans ");
    std::string nan;
    {
        std::istringstream all(kin);
        std::string l;
        for (int n = 1; std::getline(all, l); ++n)
            if (n == transLine) {
                std::istringstream tok(l);
                std::string nr, key, ax, coord;
                tok >> nr >> key >> ax >> coord;
                l.replace(l.find(coord, l.find(key) + key.size() + ax.size() + 1), 1, "?");
                nan = test::replaceLine(kin, transLine, l);
            }
    }
    EXPECT_EQ(withFile(kinName, nan).rfind(fmt::format("{}:{}: Trans COORD", kinName, transLine), 0), 0u) << withFile(kinName, nan);
    // Unknown KEY, unknown axis, text after [END], missing [END].
    EXPECT_NE(withFile(kinName, std::string(kin).replace(kin.find("MachBase"), 8, "MachBasX")).find("KEY 'MachBasX' is not read"), std::string::npos);
    const size_t machA = kin.find("MachAxis  A");
    ASSERT_NE(machA, std::string::npos);
    EXPECT_NE(withFile(kinName, std::string(kin).replace(machA + 10, 1, "Q")).find("machine 'controllers-heidenhain-components' has no such axis"),
              std::string::npos);
    EXPECT_EQ(withFile(kinName, kin + "garbage\n"), fmt::format("{}:{}: only ';' comment lines may follow [END]", kinName,
                                                                static_cast<int>(std::count(kin.begin(), kin.end(), '\n')) + 1));
    EXPECT_NE(withFile(kinName, kin.substr(0, kin.find("[END]"))).find("missing [END]"), std::string::npos);
    EXPECT_EQ(withFile(kinName, "BEGIN X.TAB INCH\n"), kinName + ":1: unit 'INCH': only MM tables are read");
    // C.COM whose last row does not repeat the first (modulo axis).
    const int lastRow = static_cast<int>(std::count(com.begin(), com.begin() + static_cast<long>(com.find("[END]")), '\n'));
    std::string open = com;
    const size_t lastStart = open.rfind('\n', open.find("[END]") - 2) + 1;
    const size_t lastEnd = open.find('\n', lastStart);
    std::string lastLine = open.substr(lastStart, lastEnd - lastStart);
    lastLine.back() = lastLine.back() == '1' ? '2' : '1';
    open.replace(lastStart, lastEnd - lastStart, lastLine);
    const std::string msg = withFile("C.COM", open);
    EXPECT_EQ(msg.rfind(fmt::format("C.COM:{}:", lastRow), 0), 0u) << msg;
    EXPECT_NE(msg.find("does not close on itself"), std::string::npos) << msg;
    // A missing .COM file named in COMPTAB.
    std::vector<OutputFile> noCom;
    for (const auto& f : r.files)
        if (f.name != "X.COM") noCom.push_back(f);
    EXPECT_NE(test::inputErrorOf([&] { tnc().apply(m, noCom); }).find("COMPTAB names 'X.COM', which is not among the files"), std::string::npos);
    // No .TAB at all.
    EXPECT_EQ(test::inputErrorOf([&] { tnc().apply(m, {}); }), "<heidenhain-tnc files>: no kinematics description (.TAB)");
}


TEST(ControllerHeidenhain, MachAxisRowsCountAgainstTheCompTabEntries) {
    // iTNC 530 HSCI technical manual 07/2013 p.686: at most 100 COMPTAB entries, the MachAxis rows counted with them.
    const EmitRequest req{componentsMachine(), componentsTruth(), "x", "2024-01-01"};
    const EmitResult r = tnc().emit(req);
    const OutputFile* tab = nullptr;
    for (const auto& f : r.files)
        if (f.name.ends_with(".TAB")) tab = &f;
    ASSERT_NE(tab, nullptr);
    // Count both kinds of row in the text, before [END] (independent of the reader).
    int comptab = 0, machAxis = 0;
    std::istringstream in(tab->content);
    for (std::string line; std::getline(in, line) && line != "[END]";) {
        machAxis += line.find(" MachAxis ") != std::string::npos;
        comptab += line.find(".COM:C") != std::string::npos;
    }
    EXPECT_EQ(machAxis, 5);
    EXPECT_GT(comptab, 0);
    heidenhain::Options exact;
    exact.maxCompEntries = comptab + machAxis;
    EXPECT_NO_THROW(heidenhain::emitFiles(req, exact));
    heidenhain::Options tight;
    tight.maxCompEntries = comptab + machAxis - 1;  // the COMPTAB rows alone would still fit
    try {
        heidenhain::emitFiles(req, tight);
        FAIL() << "expected ModelError";
    } catch (const ModelError& e) {
        EXPECT_NE(std::string(e.what()).find(fmt::format("{} MachAxis rows", machAxis)), std::string::npos) << e.what();
    }
}

TEST(ControllerHeidenhain, FilesSayTheyAreForTheItnc530) {
    const EmitResult r = tnc().emit({componentsMachine(), componentsTruth(), "x", "2024-01-01"});
    for (const auto& f : r.files) EXPECT_NE(f.content.find("for the iTNC 530"), std::string::npos) << f.name;
    EXPECT_NE(std::string(tnc().description()).find("not for TNC 640 / TNC7"), std::string::npos);
    EXPECT_FALSE(tnc().checks().empty());
}

TEST(ControllerHeidenhain, RowsAndTablesAreInTheMachineCoordinates) {
    const MachineModel& base = componentsMachine();
    const MachineModel m = test::withMachineZero(base, {{"X", -250.0}, {"Z", 350.0}, {"C", 90.0}});
    DeviationSet d = test::sameDeviations(without(componentsTruth(), "EZC"), m);
    const EmitResult r = tnc().emit({m, d, "x", "2024-01-01"});
    // Oracle: EXX (a polynomial of the description's command) at the machine positions AXISPOS of X.COM: command =
    // AXISPOS - 250 mm; X is a tool-side axis, whose columns hold -error.
    const heidenhain::TncTable x = heidenhain::parseTncTable("X.COM", file(r, "X.COM").content, {"NR", "AXISPOS", "C1"});
    const DeviationDef& exx = m.deviations[m.deviationIndex("EXX")];
    ASSERT_GT(x.rows.size(), 2u);
    EXPECT_NEAR(std::stod(x.cell(0, x.column("AXISPOS"))), -500.0 + 250.0, 1e-9);
    for (size_t n = 0; n < x.rows.size(); n += 7) {
        const double p = std::stod(x.cell(n, x.column("AXISPOS")));
        EXPECT_NEAR(std::stod(x.cell(n, x.column("C1"))), -exx.basis.evaluate(p - 250.0, d.values.data() + exx.offset, false), 1e-9) << p;
    }
    const CompensationFigures f = test::evaluateBackend(tnc(), m, d, test::nonSingularSamples(m, 4), 100.0);
    test::report("heidenhain-tnc machine-zero", f);
    EXPECT_LT(f.maxAfter, 0.1 * f.maxBefore);
    // The same files read as if the description's commands were the machine coordinates are far off.
    const CompensationFigures g =
        evaluateCompensation(base, test::sameDeviations(d, base), *tnc().apply(base, r.files), test::nonSingularSamples(base, 4), 100.0);
    EXPECT_GT(g.maxAfter, 0.5);
}

TEST(ControllerHeidenhain, ATransRowThatShiftsTheDatumIsReadAndOnlyTheVolumetricFigureSeesIt) {
    // Review note: flipping the sign of the Trans X row of C on table-table-ac left the verify residual at 0.001 um.
    // The row is read: EX0C shifts the C axis line along X, after A, which turns about X, and the workpiece datum
    // follows the axis line (location errors are not wrapped back), so the whole workpiece moves along A's (measured)
    // axis line. The TCP then moves the slides by the same amount at every pose (oracle: that rigid shift along the A
    // direction of the true machine, EB0A/EC0A tilt it off X by 0.2 mrad), which no relative
    // reading (R-test, ball bar: the instrument is set at each run's start) can see; verify's volumetric figure does.
    const MachineModel m = readMachineXml(sourcePath("samples/machines/table-table-ac.xml"));
    const DeviationSet truth = readDeviationCsv(sourcePath("samples/deviations/table-table-ac-truth.csv"), m);
    const EmitResult r = tnc().emit({m, truth, "truth.csv", "2024-01-01"});
    std::vector<OutputFile> damaged = r.files;
    std::string& tab = damaged[0].content;
    ASSERT_TRUE(damaged[0].name.ends_with(".TAB"));
    const std::string row = "Trans     X     -0.005000000";  // the one Trans X row: EX0C, beside MachAxis C
    ASSERT_NE(tab.find(row), std::string::npos) << tab;
    ASSERT_EQ(tab.find(row, tab.find(row) + 1), std::string::npos) << tab;
    tab.replace(tab.find(row), row.size(), "Trans     X     0.005000000 ");
    const auto good = tnc().apply(m, r.files), bad = tnc().apply(m, damaged);
    Vec3 a = Vec3::Zero();
    const Kinematics k(m, truth);
    for (const JointFrame& j : k.jointFrames(AxisVector::Zero(m.axisCount())))
        if (j.axis == m.requireAxis("A")) a = j.direction;
    ASSERT_NEAR(a.x(), 1.0, 1e-6);
    for (const AxisVector& q : test::nonSingularSamples(m, 3, 150.0)) {
        AxisVector shift = AxisVector::Zero(m.axisCount());
        for (int i = 0; i < 3; ++i) shift[m.requireAxis(std::string(1, "XYZ"[i]))] = 0.010 * a[i];  // +5 um read for -5 um
        EXPECT_LT((bad->driveCommandsForTool(q, 100.0) - good->driveCommandsForTool(q, 100.0) - shift).norm(), 1e-7);
    }
    MeasurementPlan plan = readPlanXml(sourcePath("samples/plans/table-table-ac-rtest.xml"));
    app::VerifyOptions o;
    o.volumetricPerAxis = 3;
    app::VerifyCompensation c;
    c.kind = app::VerifyCompensation::Kind::ControllerFiles;
    c.model = std::shared_ptr<const AppliedCompensation>(tnc().apply(m, r.files));
    const app::VerifyResult vg = app::verify(m, plan, truth, "truth", c, o);
    c.model = std::shared_ptr<const AppliedCompensation>(tnc().apply(m, damaged));
    const app::VerifyResult vb = app::verify(m, plan, truth, "truth", c, o);
    EXPECT_LT(vg.residual, 0.01 * kUm);
    EXPECT_LT(vb.residual, 0.01 * kUm);
    EXPECT_LT(vg.volumetric.maxAfter, 0.01 * kUm);
    EXPECT_NEAR(vb.volumetric.maxAfter, 10 * kUm, 0.01 * kUm);
}

}  // namespace
}  // namespace cnccomp::controllers
