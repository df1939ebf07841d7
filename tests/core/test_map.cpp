// Volumetric error map: statistics and per-point errors against closed-form effects of single deviations,
// orientation mode against axes mode, thread independence, CSV round trip, SVG content, CLI.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <span>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/inverse_kinematics.hpp"
#include "cnccomp/io/map_csv.hpp"
#include "cnccomp/io/svg_map.hpp"
#include "cnccomp/volumetric_map.hpp"
#include "test_support.hpp"

namespace cnccomp {
using namespace cnccomp::io;
namespace {

MapRequest req(const MachineModel& m, const DeviationSet& d, const char* grid, double toolLength,
               std::optional<Vec3> orientation = std::nullopt) {
    return MapRequest{m, d, parseGrid(grid), toolLength, orientation, 0};
}

const MachineModel& tableTable() {
    static const MachineModel m = readMachineXml(test::sourcePath("samples/machines/table-table-ac.xml"));
    return m;
}

TEST(MapGrid, ParsesRangesAndRejectsBadText) {
    const MapGrid g = parseGrid("X=-200:200:10, Y=0  B=-90:90:45");
    ASSERT_EQ(g.axes.size(), 3u);
    EXPECT_EQ(g.axes[0].count, 41);
    EXPECT_DOUBLE_EQ(g.axes[0].value(40), 200.0);
    EXPECT_EQ(g.axes[1].count, 1);
    EXPECT_EQ(g.size(), 41 * 5);
    long idx[3];
    g.unflatten(5 * 3 + 2, idx);
    EXPECT_EQ(idx[0], 3);
    EXPECT_EQ(idx[1], 0);
    EXPECT_EQ(idx[2], 2);
    for (const char* bad : {"", "X", "X=1:2", "X=0:10:3", "X=10:0:1", "X=0:1:0", "X=nan", "X=1 X=2", "=3", "X=0:1e12:1e-3"})
        EXPECT_THROW(parseGrid(bad), InputError) << bad;
}

TEST(Map, CAxisOffsetGivesConstantRotatingError) {
    // EX0C shifts the C line: in the workpiece frame the tip error is -Rz(-C)·(ex, 0, 0), |e| = ex everywhere.
    const MachineModel& m = test::multitasking();
    DeviationSet d(m);
    const double ex = 0.015;
    d.set("EX0C", ex);
    const VolumetricMap map = computeMap(req(m, d, "X=-100:100:50 Y=-50:50:50 C=0:330:30 B=45", 80.0));
    ASSERT_EQ(map.points.size(), 5u * 3 * 12);
    const int c = m.requireAxis("C");
    for (const MapPoint& p : map.points) {
        const double C = p.q[c];
        EXPECT_NEAR(p.error.x(), -ex * std::cos(C), 1e-12);
        EXPECT_NEAR(p.error.y(), ex * std::sin(C), 1e-12);
        EXPECT_NEAR(p.error.z(), 0.0, 1e-12);
        EXPECT_NEAR(p.tilt, 0.0, 1e-12);
    }
    EXPECT_NEAR(map.stats.norm.maxAbs, ex, 1e-12);
    EXPECT_NEAR(map.stats.norm.rms, ex, 1e-12);
    EXPECT_NEAR(map.stats.dx.maxAbs, ex, 1e-12);                  // C = 0
    EXPECT_NEAR(map.stats.dx.rms, ex / std::sqrt(2.0), 1e-12);   // mean of cos² over 12 equal steps
    EXPECT_EQ(map.stats.points, 180);
    EXPECT_EQ(map.stats.failed, 0);
}

TEST(Map, SquarenessGrowsLinearlyAlongTheAxis) {
    // EC0Y rotates the X slide about Z by g: at B = 0, C = 0 the error is x·(cos g − 1, sin g, 0).
    const MachineModel& m = test::multitasking();
    DeviationSet d(m);
    const double g = 20 * kArcsec;
    d.setLinkValue("EC0Y", g);  // the X slide turned (ISO EC0Y = -g on this machine)
    const VolumetricMap map = computeMap(req(m, d, "X=-200:200:25 Y=-100:100:100 Z=0:100:50", 150.0));
    const int x = m.requireAxis("X");
    for (const MapPoint& p : map.points) {
        EXPECT_NEAR(p.error.x(), p.q[x] * (std::cos(g) - 1), 1e-12);
        EXPECT_NEAR(p.error.y(), p.q[x] * std::sin(g), 1e-12);
        EXPECT_NEAR(p.error.z(), 0.0, 1e-12);
    }
    EXPECT_NEAR(map.stats.norm.maxAbs, 200 * 2 * std::sin(g / 2), 1e-12);
    EXPECT_EQ(std::abs(map.stats.worst.q[x]), 200.0);
    EXPECT_EQ(map.stats.worstIndex, 0);  // first of the tied extremes, X = -200
    // RMS of |x|·2 sin(g/2) over X = -200..200 step 25 (17 values), independent of Y, Z.
    double s = 0;
    for (int k = 0; k <= 16; ++k) s += std::pow((-200 + 25 * k) * 2 * std::sin(g / 2), 2);
    EXPECT_NEAR(map.stats.norm.rms, std::sqrt(s / 17), 1e-12);
}

TEST(Map, TiltOfTheAAxisIsTheToolTiltEverywhere) {
    // EB0A turns the A axis about Y: the tool axis seen from the table is off by exactly that angle at any A, C.
    const MachineModel& m = tableTable();
    DeviationSet d(m);
    d.set("EB0A", 15 * kArcsec);
    const MapStatistics s = mapStatistics(req(m, d, "X=-50:50:50 A=-90:90:30 C=0:315:45 Z=100", 50.0));
    EXPECT_EQ(s.points, 3 * 7 * 8);
    EXPECT_NEAR(s.tilt.maxAbs, 15 * kArcsec, 1e-13);
    EXPECT_NEAR(s.tilt.rms, 15 * kArcsec, 1e-13);
}

TEST(Map, ThreadCountDoesNotChangeTheResult) {
    const MachineModel& m = test::multitasking();
    DeviationSet d(m);
    for (const auto& def : m.deviations) d.set(def.name, def.isAngle() ? 7 * kArcsec : 0.009);
    MapRequest r = req(m, d, "X=-200:200:20 Y=-100:100:20 B=-90:90:30 C=0:270:90", 100.0);
    r.threads = 1;
    const VolumetricMap one = computeMap(r);
    r.threads = 5;
    const VolumetricMap five = computeMap(r);
    ASSERT_EQ(one.points.size(), five.points.size());
    for (size_t i = 0; i < one.points.size(); ++i) ASSERT_EQ(one.points[i].error, five.points[i].error);
    EXPECT_EQ(one.stats.worstIndex, five.stats.worstIndex);
    EXPECT_EQ(one.stats.norm.maxAbs, five.stats.norm.maxAbs);
    EXPECT_NEAR(one.stats.norm.rms, five.stats.norm.rms, 1e-15);
    // Statistics recomputed serially from the stored points.
    double sum = 0, mx = 0;
    for (const MapPoint& p : one.points) sum += p.error.squaredNorm(), mx = std::max(mx, p.error.norm());
    EXPECT_EQ(one.stats.norm.maxAbs, mx);
    EXPECT_NEAR(one.stats.norm.rms, std::sqrt(sum / one.points.size()), 1e-15);
    const MapStatistics fast = mapStatistics(r);
    EXPECT_EQ(fast.norm.maxAbs, mx);
    EXPECT_EQ(fast.worstIndex, one.stats.worstIndex);
}

TEST(Map, FixedOrientationSolvesTheNominalInverse) {
    const MachineModel& m = tableTable();
    DeviationSet d(m);
    d.set("EY0A", 0.02);
    d.set("EB0C", 10 * kArcsec);
    const Vec3 k = Vec3(0.3, -0.2, -1).normalized();
    MapRequest r = req(m, d, "X=-100:100:50 Y=-100:100:50 Z=0:60:30", 120.0, k);
    const VolumetricMap map = computeMap(r);
    EXPECT_EQ(map.stats.failed, 0);
    // One branch of the inverse for the whole grid: the orientation fixes A and C on a table-table machine.
    for (const MapPoint& p : map.points) {
        EXPECT_TRUE(p.ok);
        EXPECT_NEAR(p.q[m.requireAxis("A")], map.points[0].q[m.requireAxis("A")], 1e-9);
        EXPECT_NEAR(p.q[m.requireAxis("C")], map.points[0].q[m.requireAxis("C")], 1e-9);
    }
    const Kinematics nominal(m), actual(m, d);
    const Vec3 tip = nominal.toolPoint(120.0);
    for (size_t i = 0; i < map.points.size(); ++i) {
        const MapPoint& p = map.points[i];
        AxisVector q(m.axisCount());
        for (int a = 0; a < m.axisCount(); ++a) q[a] = p.q[a];
        const ToolPose n = toolPose(nominal, q, tip), e = toolPose(actual, q, tip);
        long idx[3];
        map.grid.unflatten(static_cast<long>(i), idx);
        EXPECT_NEAR((n.tip - Vec3(map.grid.axes[0].value(idx[0]), map.grid.axes[1].value(idx[1]), map.grid.axes[2].value(idx[2]))).norm(), 0, 1e-8);
        EXPECT_NEAR((n.axis - k).norm(), 0, 1e-9);
        EXPECT_NEAR((p.error - (e.tip - n.tip)).norm(), 0, 1e-15);
    }
    r.grid = parseGrid("A=0");
    EXPECT_THROW(computeMap(r), InputError);  // rotary axes are not grid names in orientation mode
}

TEST(Map, RejectsUnknownAxesAndTravel) {
    const MachineModel& m = test::multitasking();
    DeviationSet d(m);
    EXPECT_THROW(computeMap(req(m, d, "Q=0:1:1", 0.0)), InputError);
    EXPECT_THROW(computeMap(req(m, d, "Y=-400:0:100", 0.0)), ModelError);   // Y travel ±300
    EXPECT_THROW(computeMap(req(m, d, "X=0", std::nan(""))), ModelError);
}

TEST(Map, CsvRoundTripAndSvgPicture) {
    const MachineModel& m = test::multitasking();
    DeviationSet d(m);
    d.set("EX0C", 0.01);
    d.setLinkValue("EC0Y", 5 * kArcsec);
    const VolumetricMap map = computeMap(req(m, d, "X=-100:100:20 Y=-60:60:20 Z=0 B=30 C=0:90:90", 100.0));
    test::ScratchDir dir("map_csv");
    writeMapCsv(dir.file("m.csv"), map, m, {m.name, "truth.csv"});
    const MapCsvTable back = readMapCsv(dir.file("m.csv"));
    ASSERT_EQ(back.axisNames, m.axisNames);
    ASSERT_EQ(back.points.size(), map.points.size());
    for (size_t i = 0; i < map.points.size(); ++i) {
        EXPECT_NEAR((back.points[i].error - map.points[i].error).norm(), 0, 1e-8);
        EXPECT_NEAR(back.points[i].tilt, map.points[i].tilt, 1e-10);
        for (int a = 0; a < m.axisCount(); ++a) EXPECT_NEAR(back.points[i].q[a], map.points[i].q[a], 1e-6);
    }
    test::writeText(dir.file("bad.csv"), "X_mm,x_mm,y_mm,z_mm,dx_um,dy_um,dz_um,e_um,ea_arcsec,eb_arcsec,ec_arcsec,tilt_arcsec,ok\n1,2,3,4,5,x,7,8,9,10,11,12,1\n");
    try {
        readMapCsv(dir.file("bad.csv"));
        FAIL() << "bad number accepted";
    } catch (const InputError& e) {
        EXPECT_EQ(e.line(), 2);
    }
    const std::string svg = renderMapSvg(map, m, parseMapPlane("XY@C=90"), {"test"});
    EXPECT_EQ(svg.rfind("<svg", 0), 0u);
    EXPECT_NE(svg.find("C=90 deg"), std::string::npos);
    EXPECT_NE(svg.find("|e| (µm)"), std::string::npos);
    EXPECT_NE(svg.find("X axis position (mm)"), std::string::npos);
    EXPECT_NE(svg.find("marker-end"), std::string::npos);
    EXPECT_EQ(svg.find("nan"), std::string::npos);
    EXPECT_EQ(std::count(svg.begin(), svg.end(), '<') , std::count(svg.begin(), svg.end(), '>'));
    EXPECT_THROW(renderMapSvg(map, m, parseMapPlane("XY@C=45"), {}), InputError);   // not a grid value
    EXPECT_THROW(renderMapSvg(map, m, parseMapPlane("XZ"), {}), InputError);        // Z is not a range
    EXPECT_THROW(parseMapPlane("X@Z=0"), InputError);
}

/// A sink that keeps every block it is handed, checking the order.
class CollectingSink : public MapSink {
public:
    std::vector<MapPoint> points;
    int slots = 0;
    void begin(int n, long) override { slots = n; }
    void inOrder(int slot, long first, std::span<const MapPoint> block) override {
        EXPECT_GE(slot, 0);
        EXPECT_LT(slot, slots);
        EXPECT_EQ(first, static_cast<long>(points.size()));  // flat-index order, no gap
        points.insert(points.end(), block.begin(), block.end());
    }
};

bool samePoint(const MapPoint& a, const MapPoint& b) {
    return a.q == b.q && a.tip == b.tip && a.error == b.error && a.rotation == b.rotation && a.tilt == b.tilt && a.ok == b.ok;
}

TEST(Map, StreamedBlocksAreTheWholeMap) {
    // Oracle: computeMap's stored points (the same kernel, held whole). Every block once, in order, bit for bit; the
    // statistics do not depend on the thread count (summed block by block).
    const MachineModel& m = test::multitasking();
    DeviationSet d(m);
    for (const auto& def : m.deviations) d.set(def.name, def.isAngle() ? 7 * kArcsec : 0.009);
    MapRequest r = req(m, d, "X=-200:200:10 Y=-100:100:20 B=-90:90:30 C=0:270:90", 100.0);  // 41·11·7·4 = 12628
    r.threads = 1;
    const VolumetricMap whole = computeMap(r);
    for (int threads : {1, 2, 3}) {
        r.threads = threads;
        CollectingSink sink;
        const MapStatistics s = streamMap(r, sink);
        ASSERT_EQ(sink.points.size(), whole.points.size());
        for (size_t i = 0; i < whole.points.size(); ++i) ASSERT_TRUE(samePoint(sink.points[i], whole.points[i])) << i;
        EXPECT_EQ(s.norm.rms, whole.stats.norm.rms) << threads;
        EXPECT_EQ(s.tilt.rms, whole.stats.tilt.rms) << threads;
        EXPECT_EQ(s.worstIndex, whole.stats.worstIndex);
        EXPECT_EQ(s.points, whole.stats.points);
    }
}

TEST(Map, StreamedCsvAndPictureAreTheHeldMapsBytes) {
    // Oracle: writeMapCsv / renderMapSvg of computeMap's whole map. Both modes (machine axes; a fixed orientation,
    // where every point solves the inverse kinematics), two thread counts; the plane's points kept on the way.
    const MachineModel& m = test::multitasking();
    DeviationSet d(m);
    d.set("EX0C", 0.01);
    d.setLinkValue("EC0Y", 5 * kArcsec);
    d.set("EA0C1", -9 * kArcsec);
    test::ScratchDir dir("map_stream");
    struct Case {
        MapRequest request;
        const char* plane;
    };
    DeviationSet tt(tableTable());
    tt.set("EY0A", 0.02);
    tt.set("EB0C", 10 * kArcsec);
    std::vector<Case> cases;
    cases.push_back({req(m, d, "X=-100:100:5 Y=-60:60:20 Z=0 B=-30:30:30 C=0:90:90", 100.0), "XY@B=30,C=90"});
    cases.push_back({req(tableTable(), tt, "X=-100:100:50 Y=-100:100:25 Z=0:60:30", 120.0, Vec3(0.3, -0.2, -1).normalized()),
                     "XY@Z=30"});
    for (Case& c : cases) {
        const MachineModel& mm = c.request.machine;
        const VolumetricMap whole = computeMap(c.request);
        writeMapCsv(dir.file("whole.csv"), whole, mm, {mm.name, "truth.csv"});
        const MapPlane plane = parseMapPlane(c.plane);
        const std::string svg = renderMapSvg(whole, mm, plane, {"t"});
        for (int threads : {1, 2}) {
            c.request.threads = threads;
            VolumetricMap head = describeMap(c.request);
            const std::vector<long> keep = planePointIndices(head, plane);
            std::vector<MapPoint> kept;
            head.stats = streamMapCsv(dir.file("streamed.csv"), c.request, {mm.name, "truth.csv"}, keep, &kept);
            EXPECT_EQ(test::readText(dir.file("streamed.csv")), test::readText(dir.file("whole.csv"))) << c.plane;
            ASSERT_EQ(kept.size(), keep.size());
            for (size_t k = 0; k < keep.size(); ++k) EXPECT_TRUE(samePoint(kept[k], whole.points[keep[k]]));
            EXPECT_EQ(renderMapSvg(head, kept, mm, plane, {"t"}), svg);
        }
    }
    EXPECT_THROW(planePointIndices(describeMap(cases[0].request), parseMapPlane("XY@C=45")), InputError);
}

TEST(Map, AFailingSinkStopsTheStreamAndLeavesNoFile) {
    const MachineModel& m = test::multitasking();
    DeviationSet d(m);
    d.set("EX0C", 0.01);
    class Failing : public MapSink {
    public:
        int blocks = 0;
        void inOrder(int, long, std::span<const MapPoint>) override {
            if (++blocks == 3) throw ModelError("sink failed");
        }
    } sink;
    MapRequest r = req(m, d, "X=-200:200:1 Y=-100:100:10 C=0:90:90", 50.0);  // 401·21·2 = 16842 points, 16 blocks
    r.threads = 2;
    EXPECT_THROW(streamMap(r, sink), ModelError);
    EXPECT_EQ(sink.blocks, 3);
    test::ScratchDir dir("map_stream_fail");
    EXPECT_THROW(streamMapCsv(dir.file("m.csv"), r, {m.name, "x"}, std::vector<long>{5, 3}), ModelError);  // not increasing
    EXPECT_FALSE(std::filesystem::exists(dir.file("m.csv")));
}

TEST(Map, AWorkerThatFailsStopsTheStreamAtItsBlock) {
    // A block whose evaluation fails (here the sink's `evaluated`, on a worker thread): streamMap throws that error
    // after handing on exactly the blocks before it, with one to four threads (the other workers are waiting for a
    // slot or evaluating later blocks; none may hang), and a failure in the first and in the last block.
    const MachineModel& m = test::multitasking();
    DeviationSet d(m);
    d.set("EX0C", 0.01);
    MapRequest r = req(m, d, "X=-200:200:1 Y=-100:100:10 C=0:90:90", 50.0);  // 16842 points, 16 blocks of 1053
    class Failing : public MapSink {
    public:
        explicit Failing(long failAt) : failAt_(failAt) {}
        std::atomic<int> evaluatedBlocks{0};
        std::vector<long> handedOn;
        void evaluated(int, long first, std::span<const MapPoint>) override {
            ++evaluatedBlocks;
            if (first == failAt_) throw ModelError(fmt::format("block at {} failed", first));
        }
        void inOrder(int, long first, std::span<const MapPoint>) override { handedOn.push_back(first); }

    private:
        long failAt_;
    };
    for (int threads : {1, 2, 3, 4}) {
        for (long failBlock : {0L, 5L, 15L}) {
            r.threads = threads;
            Failing sink(failBlock * 1053);
            try {
                streamMap(r, sink);
                ADD_FAILURE() << "no error, " << threads << " threads";
            } catch (const ModelError& e) {
                EXPECT_NE(std::string(e.what()).find(fmt::format("block at {} failed", failBlock * 1053)), std::string::npos) << e.what();
            }
            ASSERT_EQ(sink.handedOn.size(), static_cast<size_t>(failBlock)) << threads << " threads";
            for (long b = 0; b < failBlock; ++b) EXPECT_EQ(sink.handedOn[static_cast<size_t>(b)], b * 1053);
            EXPECT_LE(sink.evaluatedBlocks.load(), 16);
        }
    }
}

TEST(Map, CommandLine) {
    test::ScratchDir dir("map_cli");
    const std::string machine = test::sourcePath("samples/machines/multitasking.xml");
    const std::string dev = test::sourcePath("samples/deviations/multitasking-truth.csv");
    const auto r = test::runCli("map --machine " + machine + " --deviations " + dev +
                                " --grid 'X=-100:100:50 Y=-100:100:50 Z=0 B=30' --tool-length 100 --out " +
                                dir.file("m.csv") + " --svg " + dir.file("m.svg") + " --plane XY@Z=0");
    ASSERT_EQ(r.exitCode, 0) << r.out;
    EXPECT_NE(r.out.find("worst |e|"), std::string::npos);
    EXPECT_EQ(readMapCsv(dir.file("m.csv")).points.size(), 25u);
    EXPECT_NE(test::readText(dir.file("m.svg")).find("</svg>"), std::string::npos);
    const auto bad = test::runCli("map --machine " + machine + " --deviations " + dev + " --grid 'X=0:1' --out " + dir.file("x.csv"));
    EXPECT_EQ(bad.exitCode, 2);
    EXPECT_NE(bad.out.find("--grid"), std::string::npos);
    EXPECT_FALSE(std::filesystem::exists(dir.file("x.csv")));
    const auto over = test::runCli("map --machine " + machine + " --deviations " + dev + " --grid 'X=0' --out " + dev);
    EXPECT_EQ(over.exitCode, 2);
    EXPECT_NE(over.out.find("refusing to overwrite"), std::string::npos);
}

}  // namespace
}  // namespace cnccomp
