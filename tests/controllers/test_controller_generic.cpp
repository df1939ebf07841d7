// Generic backend: the deviation set read back from CSV and JSON, the grid map against the exact model and its
// JSON twin, emit → apply (map lookup) ≥ 90 % less tip error, goldens, readers.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <sstream>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/inverse_kinematics.hpp"
#include "controllers/common/evaluate.hpp"
#include "controllers/generic/deviation_json.hpp"
#include "controllers/generic/generic_backend.hpp"
#include "controllers/generic/grid_map.hpp"
#include "cnccomp/io/json.hpp"
#include "controller_test_util.hpp"
#include "test_controller_common_support.hpp"

namespace cnccomp::controllers {
using namespace cnccomp::controllers::common;
using namespace cnccomp::io;
namespace {

using namespace testing;

const std::vector<Sample> kGolden = {{"multitasking", "multitasking-truth"},
                                     {"table-table-ac", "map-table-table-ac"},
                                     {"tilting-head-b", "map-tilting-head-b"}};
const std::vector<Sample> kAll = {{"multitasking", "multitasking-truth"},
                                  {"table-table-ac", "map-table-table-ac"},
                                  {"tilting-head-b", "map-tilting-head-b"},
                                  {"controllers-table-table-ac", "controllers-table-table-ac"},
                                  {"controllers-tilting-head-b", "controllers-tilting-head-b"}};

EmitResult emitSample(const Sample& s, const DeviationSet& d) { return testing::emitSample("generic", s, d); }

/// The goldens and the reader tests use a coarse map (2 um): the file format is the same, the files stay small.
generic::GridMapOptions coarse() {
    generic::GridMapOptions o;
    o.tolerance = 2 * kUm;
    return o;
}
EmitResult emitCoarse(const Sample& s, const DeviationSet& d) {
    return generic::emitFiles({machine(s.machine), d, s.deviations + ".csv", "2024-01-01"}, coarse());
}

TEST(ControllerGeneric, MapLookupLeavesLessThanATenthOfAMicrometre) {
    // Oracle: the exact erroneous kinematics at the commands the map lookup sends (evaluate.hpp), at poses that fall
    // between the nodes. The map's nodes keep each axis' interpolation within 0.05 um (GridMapOptions), so the sum over
    // two rotary axes stays below 0.1 um; a machine with component errors on every axis exceeds the node budget at
    // 0.05 um and gets a coarser map, which says so (twice its tolerance then).
    const Backend& b = backend("generic");
    for (const Sample& s : kAll) {
        const MachineModel& m = machine(s.machine);
        const DeviationSet d = deviations(s);
        const EmitResult r = emitSample(s, d);
        EXPECT_TRUE(r.notCompensated.empty()) << s.machine;
        const double tolerance = generic::buildGridMap(m, d).tolerance;
        EXPECT_NE(r.compensated.at(0).note.find(fmt::format("within {:g} um", tolerance / kUm)), std::string::npos);
        for (double L : {0.0, 150.0}) {
            const CompensationFigures f = emitApplyEvaluate(b, m, d, workspaceSamples(m, 6), L);
            std::cout << fmt::format("[generic] {:<28} L={:5.1f}: max {:8.3f} -> {:7.3f} um, rms {:7.3f} -> {:6.3f} um ({} points)\n",
                                     s.machine, L, f.maxBefore / kUm, f.maxAfter / kUm, f.rmsBefore / kUm, f.rmsAfter / kUm,
                                     f.points);
            EXPECT_GT(f.maxBefore, 5 * kUm);
            EXPECT_LT(f.maxAfter, std::max(0.1 * kUm, 2 * tolerance)) << s.machine << " L=" << L;
        }
    }
}

TEST(ControllerGeneric, MapNodesFollowTheToleranceAndTheTableNodes) {
    // The midpoint deviation goes as h^2: a quarter of the tolerance takes about twice the rotary nodes. A table-type
    // component error puts its nodes on the map (its kinks); linear axes with location errors only keep two nodes.
    const Sample s{"tilting-head-b", "tilting-head-b-truth"};
    const MachineModel& m = machine(s.machine);
    const DeviationSet d = deviations(s);
    generic::GridMapOptions fine = coarse(), finer = coarse();
    fine.tolerance = 0.2 * kUm;
    finer.tolerance = 0.05 * kUm;
    const generic::GridMap a = generic::buildGridMap(m, d, fine), b = generic::buildGridMap(m, d, finer);
    const int B = m.requireAxis("B");
    const auto& na = a.axes[static_cast<size_t>(B)].nodes;
    const auto& nb = b.axes[static_cast<size_t>(B)].nodes;
    EXPECT_GT(nb.size(), na.size() * 3 / 2);
    for (double n : m.deviations[static_cast<size_t>(m.deviationIndex("EXB"))].basis.nodes) {
        EXPECT_NE(std::find_if(na.begin(), na.end(), [&](double x) { return std::abs(x - n) < 1e-12; }), na.end()) << n / kDeg;
    }
    for (int k : {m.requireAxis("X"), m.requireAxis("Y"), m.requireAxis("Z")}) EXPECT_EQ(b.axes[static_cast<size_t>(k)].nodes.size(), 2u);
}

TEST(ControllerGeneric, MapNodesHoldTheExactErrorAndInterpolateExactlyAlongLinearAxes) {
    const Sample& s = kGolden[0];
    const MachineModel& m = machine(s.machine);
    const DeviationSet d = deviations(s);
    const generic::GridMap g = generic::buildGridMap(m, d, coarse());
    const Kinematics nominal(m), actual(m, d);
    const auto& bNodes = g.axes[static_cast<size_t>(m.requireAxis("B"))].nodes;
    const auto& cNodes = g.axes[static_cast<size_t>(m.requireAxis("C"))].nodes;
    // The nodes follow the tolerance (location errors only: few), so the test takes every B node and a middle C node.
    ASSERT_GE(bNodes.size(), 2u);
    ASSERT_GE(cNodes.size(), 2u);
    // Location errors only: at fixed rotary nodes the tip error is affine in each linear axis, so the two-node
    // interpolation is exact anywhere along X, Y, Z (an independent check of both the map and the lookup).
    for (double x : {-433.0, 17.0, 650.0})
        for (double y : {-250.0, 99.0})
            for (const double b : bNodes) {
                AxisVector q = AxisVector::Zero(m.axisCount());
                q[m.requireAxis("X")] = x;
                q[m.requireAxis("Y")] = y;
                q[m.requireAxis("Z")] = 321.0;
                q[m.requireAxis("B")] = b;
                q[m.requireAxis("C")] = cNodes[cNodes.size() / 2];
                Vec3 e0, dk;
                g.at(q, e0, dk);
                const Vec3 tip = nominal.toolPoint(80.0);
                // The map is along the machine's X Y Z: the workpiece-frame error turned by the nominal workpiece orientation.
                const Vec3 exact = nominal.baseToWorkpiece(q).linear() * (toolPose(actual, q, tip).tip - toolPose(nominal, q, tip).tip);
                EXPECT_NEAR((e0 + 80.0 * dk - exact).norm(), 0.0, 1e-9);
            }
}

TEST(ControllerGeneric, DeviationFilesAndMapJsonReadBack) {
    for (const Sample& s : kAll) {
        const MachineModel& m = machine(s.machine);
        const DeviationSet d = deviations(s);
        const EmitResult r = emitSample(s, d);
        const DeviationSet j = generic::readDeviationJson(requireFile(r.files, "deviations.json", "t").content, "deviations.json", m);
        EXPECT_EQ(j.present, d.present);
        EXPECT_EQ((j.values - d.values).cwiseAbs().maxCoeff(), 0.0) << s.machine;  // shortest round-trip numbers
        test::ScratchDir dir("generic_dev");
        test::writeText(dir.file("d.csv"), requireFile(r.files, "deviations.csv", "t").content);
        const DeviationSet c = readDeviationCsv(dir.file("d.csv"), m);
        EXPECT_LT((c.values - d.values).cwiseAbs().maxCoeff(), 1e-9);
        // map.json carries the numbers of map.csv.
        const generic::GridMap g = generic::parseGridMapCsv(requireFile(r.files, "map.csv", "t").content, "map.csv", m);
        const Json mj = parseJson(requireFile(r.files, "map.json", "t").content, "map.json");
        const auto dx = mj.require("dx_machine_um", Json::Type::Array, "map.json").numbers("map.json");
        const auto dkz = mj.require("dkz_machine_urad", Json::Type::Array, "map.json").numbers("map.json");
        ASSERT_EQ(dx.size(), g.tip.size());
        for (size_t i = 0; i < dx.size(); ++i) {
            EXPECT_NEAR(dx[i] * kUm, g.tip[i].x(), 1e-15);
            EXPECT_NEAR(dkz[i] * 1e-6, g.toolAxis[i].z(), 1e-15);
        }
        const auto& grid = mj.require("grid", Json::Type::Array, "map.json").array;
        ASSERT_EQ(grid.size(), g.axes.size());
        for (size_t a = 0; a < grid.size(); ++a)
            EXPECT_EQ(grid[a].require("nodes", Json::Type::Array, "map.json").array.size(), g.axes[a].nodes.size());
    }
}

TEST(ControllerGeneric, GoldenFilesAreReproducedAndReadBack) {
    for (const Sample& s : kGolden) {
        const EmitResult r = emitCoarse(s, deviations(s));
        const std::vector<OutputFile> golden = compareWithGolden("generic", s.machine, r);
        const auto comp = backend("generic").apply(machine(s.machine), golden);
        EXPECT_TRUE(comp->driveCommands(AxisVector::Zero(machine(s.machine).axisCount())).allFinite());
    }
}

TEST(ControllerGeneric, ReadersNameFileAndLine) {
    using namespace generic;
    EXPECT_EQ(inputErrorLine([] { parseJson("{\n \"a\": [1,\n 2,,\n 3]}", "x.json"); }), 3);
    EXPECT_EQ(inputErrorLine([] { parseJson("{\"a\": 1, \"a\": 2}", "x.json"); }), 1);
    EXPECT_EQ(inputErrorLine([] { parseJson("{\"a\": nan}", "x.json"); }), 1);
    EXPECT_EQ(inputErrorLine([] { parseJson("[1] 2", "x.json"); }), 1);
    const MachineModel& m = machine("multitasking");
    EXPECT_EQ(inputErrorLine([&] {
                  readDeviationJson("{\"format\": \"cnccomp-deviations\", \"deviations\": [\n{\"name\": \"EQ0Q\"}]}", "d.json", m);
              }),
              2);
    const EmitResult r = emitCoarse(kGolden[0], deviations(kGolden[0]));
    std::string csv = requireFile(r.files, "map.csv", "t").content;
    const size_t last = csv.rfind('\n', csv.size() - 2);
    const std::string cut = csv.substr(0, last + 1);  // one row missing: not a full grid
    EXPECT_THROW(parseGridMapCsv(cut, "map.csv", m), InputError);
    std::string bad = csv;
    bad.replace(bad.rfind(','), 1, ",x");
    const int lines = static_cast<int>(std::count(csv.begin(), csv.end(), '\n'));
    EXPECT_EQ(inputErrorLine([&] { parseGridMapCsv(bad, "map.csv", m); }), lines);
    EXPECT_THROW(parseGridMapCsv(csv, "map.csv", machine("table-table-ac")), InputError);
}


TEST(ControllerGeneric, MapAxisColumnsAreMachineCoordinates) {
    const Sample s{"tilting-head-b", "map-tilting-head-b"};
    const MachineModel& base = machine(s.machine);
    const MachineModel m = test::withMachineZero(base, {{"X", -250.0}, {"B", 30.0}});
    const DeviationSet d = test::sameDeviations(deviations(s), m);
    const EmitResult r = backend("generic").emit({m, d, "x", "2024-01-01"});
    // Oracle: by hand. X travels -800..800 mm and B -120..120 deg in the description: -550..1050 mm and -150..90 deg
    // from the controller's machine zeros. Read the columns without the reader.
    std::istringstream in(requireFile(r.files, "map.csv", "test").content);
    std::string line;
    std::vector<std::string> head;
    double xmin = 1e9, xmax = -1e9, bmin = 1e9, bmax = -1e9;
    int ix = -1, ib = -1;
    while (std::getline(in, line)) {
        if (line.empty() || line[0] == '#') continue;
        std::vector<std::string> cells;
        std::stringstream ls(line);
        for (std::string c; std::getline(ls, c, ',');) cells.push_back(c);
        if (head.empty()) {
            head = cells;
            for (size_t k = 0; k < head.size(); ++k) {
                if (head[k].rfind("X", 0) == 0) ix = static_cast<int>(k);
                if (head[k].rfind("B", 0) == 0) ib = static_cast<int>(k);
            }
            continue;
        }
        xmin = std::min(xmin, std::stod(cells[ix]));
        xmax = std::max(xmax, std::stod(cells[ix]));
        bmin = std::min(bmin, std::stod(cells[ib]));
        bmax = std::max(bmax, std::stod(cells[ib]));
    }
    ASSERT_GE(ix, 0);
    ASSERT_GE(ib, 0);
    EXPECT_DOUBLE_EQ(xmin, -550.0);
    EXPECT_DOUBLE_EQ(xmax, 1050.0);
    EXPECT_DOUBLE_EQ(bmin, -150.0);
    EXPECT_DOUBLE_EQ(bmax, 90.0);
    const CompensationFigures f = emitApplyEvaluate(backend("generic"), m, d, workspaceSamples(m, 6), 100.0);
    EXPECT_LT(f.maxAfter, 0.1 * kUm);
}

}  // namespace
}  // namespace cnccomp::controllers
