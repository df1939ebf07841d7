// Reversal values in the deviation set (DeviationSet::reversal, rows B<axis> of the deviation CSV): round trip and bad
// input; the laser's mean reversal B̄ → set → `emit --controller linuxcnc` BACKLASH = −B̄ (oracle: B̄ computed in this test
// from the sample file's readings, independently of laser_positioning.cpp: (Σ x↑ − Σ x↓) / (runs · targets), which is
// ISO 230-2's mean of B_i = x̄_i↑ − x̄_i↓ for equal run counts); the circles' backlash → the set's reversal (oracle: the
// simulated truth, the circle model's backlash signature added to kinematically simulated traces).
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

#include <fmt/format.h>

#include "cnccomp/deviations.hpp"
#include "cnccomp/error.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/linear_circle_trace.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "cnccomp/linear_circle_identify.hpp"
#include "cnccomp/linear_circle_run.hpp"
#include "cnccomp/units.hpp"
#include "test_support.hpp"

namespace cnccomp {
using namespace cnccomp::io;
using namespace cnccomp::measurement;
namespace {

std::string readText(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

void writeText(const std::string& path, const std::string& text) {
    std::ofstream(path, std::ios::binary) << text;
}

TEST(Reversal, CsvRoundTripAndFilesWithoutReversalUnchanged) {
    const MachineModel& m = test::sampleMachine("mill-3axis");
    const test::ScratchDir dir("reversal-csv");
    // A sample set without reversal rows: written byte for byte as before (its text holds no B row).
    const std::string sample = test::sourcePath("samples/deviations/mill-3axis-truth.csv");
    const DeviationSet truth = readDeviationCsv(sample, m);
    EXPECT_FALSE(truth.hasReversal());
    const std::string text = formatDeviationCsv(truth);
    EXPECT_EQ(text.find("\nB"), std::string::npos) << text;
    DeviationSet with = truth;
    with.setReversal("X", -3.25 * kUm);
    with.setReversal("Z", 1.5 * kUm);
    const std::string withText = formatDeviationCsv(with);
    // The reversal rows follow the deviations' rows unchanged.
    EXPECT_EQ(withText, text + "BX,,-3.250000,um,\nBZ,,1.500000,um,\n");
    writeText(dir.file("d.csv"), withText);
    const DeviationSet back = readDeviationCsv(dir.file("d.csv"), m);
    EXPECT_EQ(back.reversalPresent, (std::vector<char>{1, 0, 1}));
    EXPECT_NEAR(back.reversal[0] / kUm, -3.25, 1e-12);
    EXPECT_NEAR(back.reversal[2] / kUm, 1.5, 1e-12);
    EXPECT_EQ(back.values, with.values);
    EXPECT_EQ(formatDeviationCsv(back), withText);
    // In mm too.
    writeText(dir.file("mm.csv"), "name,alias,value,unit\nBY,,0.002,mm\n");
    EXPECT_NEAR(readDeviationCsv(dir.file("mm.csv"), m).reversal[1] / kUm, 2.0, 1e-9);
}

TEST(Reversal, CsvRefusesUnknownOrRotaryAxesAndBadRows) {
    const test::ScratchDir dir("reversal-bad");
    const auto error = [&](const MachineModel& m, const std::string& rows) -> std::string {
        writeText(dir.file("bad.csv"), "name,alias,value,unit\n" + rows);
        try {
            readDeviationCsv(dir.file("bad.csv"), m);
        } catch (const InputError& e) {
            return e.what();
        }
        return "no error";
    };
    const MachineModel& mill = test::sampleMachine("mill-3axis");
    const std::string q = error(mill, "EC0Y,,1,arcsec\nBQ,,2,um\n");
    EXPECT_NE(q.find("bad.csv:3"), std::string::npos) << q;
    EXPECT_NE(q.find("has no axis Q"), std::string::npos) << q;
    const std::string unit = error(mill, "BX,,2,arcsec\n");
    EXPECT_NE(unit.find("bad.csv:2"), std::string::npos) << unit;
    EXPECT_NE(unit.find("is a length"), std::string::npos) << unit;
    const std::string twice = error(mill, "BX,,2,um\nBX,,3,um\n");
    EXPECT_NE(twice.find("bad.csv:3"), std::string::npos) << twice;
    EXPECT_NE(twice.find("first on line 2"), std::string::npos) << twice;
    EXPECT_NE(error(mill, "BX,EXX,2,um\n").find("takes no alias"), std::string::npos);
    EXPECT_NE(error(mill, "BX,,1e9,um\n").find("beyond"), std::string::npos);
    const std::string rotary = error(test::sampleMachine("table-table-ac"), "BA,,2,um\n");
    EXPECT_NE(rotary.find("bad.csv:2"), std::string::npos) << rotary;
    EXPECT_NE(rotary.find("rotary"), std::string::npos) << rotary;
    DeviationSet s(test::sampleMachine("table-table-ac"));
    EXPECT_THROW(s.setReversal("A", 1e-3), ModelError);
}

/// B̄ of the sample laser file (µm), computed here from its rows: (Σ x↑ − Σ x↓) / (runs · targets).
double sampleMeanReversalUm(const std::string& path, int runs, int targets) {
    std::ifstream in(path);
    std::string line;
    double up = 0, down = 0;
    int rows = 0;
    while (std::getline(in, line)) {
        if (line.empty() || line[0] == '#' || line.rfind("target", 0) == 0) continue;
        std::stringstream s(line);
        std::string target, run, direction, value;
        std::getline(s, target, ',');
        std::getline(s, run, ',');
        std::getline(s, direction, ',');
        std::getline(s, value, ',');
        (direction == "+" ? up : down) += std::stod(value);
        ++rows;
    }
    EXPECT_EQ(rows, 2 * runs * targets);
    return (up - down) / (runs * targets);
}

/// The value of `KEY = value` in section [section] of an INI text, NaN if absent.
double iniValue(const std::string& text, const std::string& section, const std::string& key) {
    std::istringstream in(text);
    std::string line, current;
    while (std::getline(in, line)) {
        if (line.rfind('[', 0) == 0) current = line.substr(1, line.find(']') - 1);
        else if (current == section && line.rfind(key + " = ", 0) == 0) return std::stod(line.substr(key.size() + 3));
    }
    return NAN;
}

TEST(Reversal, LaserMeanReversalGoesToLinuxcncBacklash) {
    const test::ScratchDir dir("reversal-laser");
    const std::string laser = test::sourcePath("samples/laser/mill-3axis-x.csv");
    const std::string machine = test::sourcePath("samples/machines/mill-3axis.xml");
    const double bBar = sampleMeanReversalUm(laser, 5, 11);
    EXPECT_NEAR(bBar, -3.0, 0.3);  // the file's comment: a reversal of 3 µm, the slide lagging
    const test::CliResult r = test::runCli(fmt::format("laser --file '{}' --machine '{}' --deviations-out '{}' --merge '{}'", laser,
                                                       machine, dir.file("set.csv"),
                                                       test::sourcePath("samples/deviations/mill-3axis-truth.csv")));
    ASSERT_EQ(r.exitCode, 0) << r.out;
    EXPECT_NE(r.out.find("BX = the mean reversal value"), std::string::npos) << r.out;
    const MachineModel& m = test::sampleMachine("mill-3axis");
    const DeviationSet set = readDeviationCsv(dir.file("set.csv"), m);
    ASSERT_TRUE(set.reversalPresent[0]);
    EXPECT_FALSE(set.reversalPresent[1]);
    EXPECT_NEAR(set.reversal[0] / kUm, bBar, 5e-7);  // the CSV holds 6 decimals of um
    EXPECT_NEAR(set.get("EC0Y") / kArcsec, readDeviationCsv(test::sourcePath("samples/deviations/mill-3axis-truth.csv"), m).get("EC0Y") / kArcsec, 1e-9);

    const test::CliResult e = test::runCli(fmt::format("emit --controller linuxcnc --machine '{}' --deviations '{}' --out '{}' "
                                                       "--copy-identified --date 2026-11-26",
                                                       machine, dir.file("set.csv"), dir.file("lc")));
    ASSERT_EQ(e.exitCode, 0) << e.out;
    // Route 1 (component, no COMP_FILE): [JOINT_0] BACKLASH = −B̄ in mm (6 decimals); no BACKLASH for Y and Z.
    const std::string kins = readText(dir.file("lc/cnccomp-kins.ini"));
    EXPECT_NEAR(iniValue(kins, "JOINT_0", "BACKLASH"), -bBar / 1000.0, 6e-7) << kins;
    EXPECT_TRUE(std::isnan(iniValue(kins, "JOINT_1", "BACKLASH"))) << kins;
    // Route 2 (pins and tables): X has a COMP_FILE (its EXX), where LinuxCNC ignores BACKLASH: the columns carry it,
    // forward − reverse = −B̄ on every line.
    const std::string pinsIni = readText(dir.file("lc/cnccomp.ini"));
    EXPECT_TRUE(std::isnan(iniValue(pinsIni, "JOINT_0", "BACKLASH"))) << pinsIni;
    std::istringstream table(readText(dir.file("lc/X.comp")));
    double nominal = 0, fwd = 0, rev = 0;
    int lines = 0;
    while (table >> nominal >> fwd >> rev) {
        EXPECT_NEAR(fwd - rev, -bBar / 1000.0, 2e-7) << nominal;
        ++lines;
    }
    EXPECT_GT(lines, 2);
}

TEST(Reversal, CircleBacklashGoesToTheReversalWithinItsInterval) {
    const MachineModel& m = test::sampleMachine("mill-3axis");
    const MeasurementPlan plan = readPlanXml(test::sourcePath("samples/plans/mill-3axis-circles.xml"));
    const LinearCircleRun& run = plan.circleRuns.at(0);  // XY, 360° from 45°: both ends of X and Y inside the data arc
    ASSERT_EQ(run.plane, LinearPlane::XY);
    // Truth: lost motion of 4 µm in X, 2.5 µm in Y (the same step at both ends) → B_X = −4, B_Y = −2.5 µm.
    LinearCircleDiagnostics d;
    d.backlash = {{{4.0, 4.0}, {2.5, 2.5}}};
    const test::ScratchDir dir("reversal-circle");
    std::vector<DirectedTrace> passes = simulateLinearCircle(Kinematics(m), run);
    std::mt19937 rng(20);
    std::normal_distribution<double> noise(0.0, 0.3e-3);
    for (DirectedTrace& t : passes) {
        LinearCirclePass p;
        p.direction = t.direction;
        p.feed = run.capture.feed;
        p.angleDeg = t.trace.angleDeg;
        p.startDeg = t.trace.angleDeg.front();
        p.sweepDeg = std::abs(t.trace.angleDeg.back() - t.trace.angleDeg.front());
        p.dL = t.trace.dL;
        const std::vector<double> with = predictLinearCircle(run.circle(), p, d, Eigen::Vector2d::Zero(), 0.0);
        for (size_t i = 0; i < with.size(); ++i) t.trace.dL[i] += with[i] + noise(rng);
    }
    writeText(dir.file(run.name + ".csv"), formatLinearCircleTrace(run, passes, false, m.name));
    const LinearCircleIdentification id = identifyLinearCircleRuns(m, {run}, dir.path.string());
    ASSERT_EQ(id.reversals.size(), 2u);
    const double truth[2] = {-4.0, -2.5};
    for (int a = 0; a < 2; ++a) {
        const LinearCircleReversal& v = id.reversals[static_cast<size_t>(a)];
        EXPECT_EQ(v.axis, a == 0 ? "X" : "Y");
        EXPECT_LE(v.lower95, truth[a]) << v.axis;
        EXPECT_GE(v.upper95, truth[a]) << v.axis;
        EXPECT_LT(v.upper95 - v.lower95, 1.0) << v.axis;
        EXPECT_NEAR(id.deviations.reversal[static_cast<size_t>(a)] / kUm, v.value, 1e-12);
        EXPECT_TRUE(id.deviations.reversalPresent[static_cast<size_t>(a)]);
    }
    EXPECT_FALSE(id.deviations.reversalPresent[2]);
}

// identify --merge: a reversal value the identification determined replaces the base's, one it did not keeps the base's,
// and the output says which (oracle: the rule, applied by hand to the values written into the base here). The plan is
// the sample's XY circle alone: it determines BX and BY (both ends of X and Y inside its data arc), not BZ.
TEST(Reversal, IdentifyMergeKeepsWhatTheRunDidNotDetermine) {
    const test::ScratchDir dir("reversal-merge");
    const std::string machine = test::sourcePath("samples/machines/mill-3axis.xml");
    const std::string samplePlan = readText(test::sourcePath("samples/plans/mill-3axis-circles.xml"));
    std::string plan;  // the sample plan without its YZ and ZX circles
    std::istringstream in(samplePlan);
    for (std::string line; std::getline(in, line);)
        if (line.find("name=\"yz\"") == std::string::npos && line.find("name=\"zx\"") == std::string::npos) plan += line + "\n";
    writeText(dir.file("xy.xml"), plan);
    ASSERT_EQ(test::runCli(fmt::format("simulate --machine '{}' --plan '{}' --deviations '{}' --out '{}'", machine, dir.file("xy.xml"),
                                       test::sourcePath("samples/deviations/mill-3axis-truth.csv"), dir.file("traces"))).exitCode, 0);
    const MachineModel& m = test::sampleMachine("mill-3axis");
    DeviationSet base(m);
    base.set("EB0Z", 7.0 * kArcsec);  // not determined by an XY circle either: kept
    base.setReversal("X", -3.0 * kUm);
    base.setReversal("Z", -1.5 * kUm);
    writeText(dir.file("base.csv"), formatDeviationCsv(base));
    const test::CliResult r = test::runCli(fmt::format("identify --machine '{}' --plan '{}' --traces '{}' --merge '{}' --out '{}'", machine,
                                                       dir.file("xy.xml"), dir.file("traces"), dir.file("base.csv"), dir.file("d.csv")));
    ASSERT_EQ(r.exitCode, 0) << r.out;
    const DeviationSet d = readDeviationCsv(dir.file("d.csv"), m);
    // Determined (the traces hold no lost motion: ~0), replacing the base's −3 µm; BY new; BZ kept exactly.
    ASSERT_TRUE(d.reversalPresent[0] && d.reversalPresent[1] && d.reversalPresent[2]);
    EXPECT_NEAR(d.reversal[0] / kUm, 0.0, 0.01);
    EXPECT_NEAR(d.reversal[1] / kUm, 0.0, 0.01);
    EXPECT_NEAR(d.reversal[2] / kUm, -1.5, 1e-9);
    EXPECT_NEAR(d.get("EB0Z") / kArcsec, 7.0, 1e-9);
    EXPECT_NEAR(d.get("EC0Y") / kArcsec, 5.0, 1e-3);
    EXPECT_NE(r.out.find("merge: BX = "), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("from this identification (replaces the base's -3.0000 um)"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("from this identification (the base had none)"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("merge: BZ = -1.5000 um kept from the base (this identification did not determine it)"), std::string::npos)
        << r.out;
}

}  // namespace
}  // namespace cnccomp
