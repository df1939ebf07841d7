// The laser's positioning error in the deviation set and the volumetric map (cnccomp/laser_deviation.hpp; `cnccomp
// laser --machine --deviations-out --merge`, `cnccomp identify --merge`, `cnccomp map`). Oracle: hand calculation from
// the sample file's readings (written out below) and the ISO 230-1 meaning of EC0Y (README "Deviation names and
// signs": Y turned by EC0Y about +Z, so a Y move of y displaces the tool by −y·sin EC0Y along X).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <sstream>
#include <string>

#include <fmt/format.h>

#include "cnccomp/deviations.hpp"
#include "cnccomp/error.hpp"
#include "cnccomp/geometry.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/laser_csv.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "cnccomp/laser_deviation.hpp"
#include "cnccomp/laser_positioning.hpp"
#include "laser_test_machines.hpp"
#include "test_support.hpp"

namespace cnccomp {
using namespace cnccomp::io;
namespace {

const std::string kLaser = test::sourcePath("samples/laser/mill-3axis-x.csv");
using test::gantryXml;
using test::kneeXml;

// Hand calculation from the file's ten readings at each target (5 runs × 2 directions, µm):
//   242.7: + 3.19 3.26 3.65 3.60 3.19, − 6.51 6.42 6.48 6.22 6.72 → x̄ = 49.24 / 10 = 4.924 µm
//  −160.9: + −5.36 −4.53 −4.37 −5.45 −5.04, − −1.49 −1.87 −1.64 −1.65 −1.56 → x̄ = −32.96 / 10 = −3.296 µm
constexpr double kMean242 = 4.924, kMeanM160 = -3.296;
// EC0Y = 5″ of the set merged into: at Y = 100 mm, dx = −100 mm · sin(5″) = −2.42407 µm.
const double kSquarenessDx = -100.0 * std::sin(5 * kArcsec) / kUm;

/// dx (µm) of the one-point map written by `cnccomp map` at X = x, Y = 100, Z = −200.
double mapDx(const test::ScratchDir& dir, const std::string& machine, const std::string& deviations, double x) {
    const std::string out = dir.file(fmt::format("map{}.csv", x));
    const test::CliResult r = test::runCli(fmt::format("map --machine '{}' --deviations '{}' --grid 'X={} Y=100 Z=-200' --out '{}'",
                                                       machine, deviations, x, out));
    EXPECT_EQ(r.exitCode, 0) << r.out;
    std::istringstream in(test::readText(out));
    std::string line, last;
    while (std::getline(in, line))
        if (!line.empty() && line[0] != '#') last = line;
    // X_mm,Y_mm,Z_mm,x_mm,y_mm,z_mm,dx_um,...
    std::istringstream row(last);
    std::string cell;
    for (int i = 0; i < 7; ++i) std::getline(row, cell, ',');
    return std::stod(cell);
}

// A set identified elsewhere (here: EC0Y = 5″, as a circle identification writes it) plus the laser's positioning error
// merged in: the map shows x̄ at the laser's target with the laser's sign (actual − target > 0 → dx > 0), added to the
// squareness' own share, on a gantry (component on the tool side) and on a knee mill (component on the table, s = −1).
TEST(LaserDeviation, TheMapOfTheCombinedSetShowsThePositioningErrorAtItsPlaceWithItsSign) {
    const test::ScratchDir dir("laser-deviation");
    for (const auto& [xml, squareness] : {std::pair{gantryXml(), "EC0Y"}, std::pair{kneeXml(), "EC0X"}}) {
        const std::string machine = dir.file(std::string(squareness) + ".xml"), base = dir.file(std::string(squareness) + "-base.csv"),
                          combined = dir.file(std::string(squareness) + "-combined.csv");
        test::writeText(machine, xml);
        // EC0X of the knee mill (X turned relative to Y) moves the tool along X by +y·sin for a Y move: the same dx as
        // EC0Y = 5″ needs EC0X = −5″ (README "Deviation names and signs": X∠Y = 90° + EC0Y, = 90° − EC0X).
        test::writeText(base, fmt::format("name,alias,value,unit\n{},,{},arcsec\n", squareness, squareness == std::string("EC0Y") ? 5 : -5));
        const test::CliResult r = test::runCli(fmt::format("laser --file '{}' --machine '{}' --deviations-out '{}' --merge '{}'",
                                                           kLaser, machine, combined, base));
        ASSERT_EQ(r.exitCode, 0) << r.out;
        EXPECT_NE(r.out.find(fmt::format("sign from the machine's kinematics: {}", squareness == std::string("EC0Y") ? "+1" : "-1")),
                  std::string::npos) << r.out;
        EXPECT_NEAR(mapDx(dir, machine, combined, 242.7), kMean242 + kSquarenessDx, 2e-5) << squareness;
        EXPECT_NEAR(mapDx(dir, machine, combined, -160.9), kMeanM160 + kSquarenessDx, 2e-5) << squareness;
        // The squareness of the base set is kept.
        const MachineModel m = readMachineXml(machine);
        EXPECT_NEAR(readDeviationCsv(combined, m).get(squareness) / kArcsec, squareness == std::string("EC0Y") ? 5 : -5, 1e-6);
    }
}

// The library: a polynomial EXX (the sample mill's scale term) gets the least-squares slope through the targets' means;
// hand check: the slope of a file whose means are exactly 0.02·P is 0.02 µm/mm, residual 0.
TEST(LaserDeviation, APolynomialComponentGetsTheLeastSquaresScale) {
    const MachineModel& m = test::sampleMachine("mill-3axis");
    LaserPositioningRuns in;
    in.axis = "Y";
    in.targets = {-200, -100, 0, 100, 200};
    for (int j = 0; j < 5; ++j) {
        std::vector<double> f, r;
        for (double P : in.targets) {
            f.push_back(0.02 * P - 1.5);
            r.push_back(0.02 * P + 1.5);
        }
        in.forward.push_back(f);
        in.reverse.push_back(r);
    }
    DeviationSet set(m);
    const LaserComponentResult c = setPositioningComponent(set, evaluateLaserPositioning(in));
    EXPECT_EQ(c.component, "EYY");
    EXPECT_NEAR(c.sensitivity, 1.0, 1e-9);
    EXPECT_NEAR(set.values[m.deviations[static_cast<size_t>(m.deviationIndex("EYY"))].offset] / kUm, 0.02, 1e-12);
    EXPECT_NEAR(c.largestResidualUm, 0.0, 1e-9);
    EXPECT_NEAR(c.meanReversalUm, -3.0, 1e-12);
}

// Bad input: the sample X file of a 0..500 mm axis against the mill's ±400 mm travel; a machine without the component.
TEST(LaserDeviation, RefusesTargetsOutsideTheTravelAndAMissingComponent) {
    const test::ScratchDir dir("laser-deviation-bad");
    const test::CliResult outside = test::runCli(fmt::format(
        "laser --file '{}' --machine '{}' --deviations-out '{}'", test::sourcePath("samples/laser/x-axis-iso230-2.csv"),
        test::sourcePath("samples/machines/mill-3axis.xml"), dir.file("d.csv")));
    EXPECT_EQ(outside.exitCode, 2) << outside.out;
    EXPECT_NE(outside.out.find("target 401.5 mm is outside the travel of X"), std::string::npos) << outside.out;
    const test::CliResult missing = test::runCli(fmt::format(
        "laser --file '{}' --machine '{}' --deviations-out '{}'", kLaser,
        test::sourcePath("samples/machines/mill-3axis-table-xy.xml"), dir.file("d.csv")));
    EXPECT_EQ(missing.exitCode, 2) << missing.out;
    EXPECT_NE(missing.out.find("has no component error 'EXX'"), std::string::npos) << missing.out;
    EXPECT_FALSE(std::filesystem::exists(dir.file("d.csv")));
}

}  // namespace
}  // namespace cnccomp

namespace cnccomp {
namespace {

// `identify --merge`: the squareness identified from the circles goes into the set the laser wrote, whose positioning
// component is kept (oracle: the truth the traces were simulated with, EC0Y = 5″, and the laser's own EXX).
TEST(LaserDeviation, IdentifyMergesTheCircleSquarenessIntoTheLaserSet) {
    const test::ScratchDir dir("laser-deviation-merge");
    const std::string machine = test::sourcePath("samples/machines/mill-3axis.xml");
    const std::string plan = test::sourcePath("samples/plans/mill-3axis-circles.xml");
    const test::CliResult laser = test::runCli(fmt::format("laser --file '{}' --machine '{}' --deviations-out '{}'", kLaser,
                                                           machine, dir.file("laser.csv")));
    ASSERT_EQ(laser.exitCode, 0) << laser.out;
    const test::CliResult sim = test::runCli(fmt::format("simulate --machine '{}' --plan '{}' --deviations '{}' --out '{}'",
                                                         machine, plan,
                                                         test::sourcePath("samples/deviations/mill-3axis-truth.csv"),
                                                         dir.file("traces")));
    ASSERT_EQ(sim.exitCode, 0) << sim.out;
    const test::CliResult id = test::runCli(fmt::format("identify --machine '{}' --plan '{}' --traces '{}' --out '{}' --merge '{}'",
                                                        machine, plan, dir.file("traces"), dir.file("all.csv"),
                                                        dir.file("laser.csv")));
    ASSERT_EQ(id.exitCode, 0) << id.out;
    EXPECT_NE(id.out.find("merged into"), std::string::npos) << id.out;
    const MachineModel& m = test::sampleMachine("mill-3axis");
    const DeviationSet laserSet = readDeviationCsv(dir.file("laser.csv"), m), all = readDeviationCsv(dir.file("all.csv"), m);
    EXPECT_NEAR(all.get("EC0Y") / kArcsec, 5.0, 1e-3);
    EXPECT_NEAR(all.get("EA0Z") / kArcsec, -4.0, 1e-3);
    const int exx = m.deviations[static_cast<size_t>(m.deviationIndex("EXX"))].offset;
    EXPECT_NEAR(all.values[exx], laserSet.values[exx], 1e-12);
    EXPECT_NEAR(all.values[exx] / kUm, 0.02014, 5e-6);  // the laser's slope, not the circles'
}

}  // namespace
}  // namespace cnccomp
