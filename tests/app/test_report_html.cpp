// The HTML report: `identify --report r.html` end to end, the page's content (self-contained, escaped, every plot also
// as its own SVG, the numbers in the JSON summary), the map pictures (scale from 0 shared, arrows clipped, µm, labelled
// coordinates, the all-zero message), and the page in a real browser: headless Chromium loads it without console
// errors, and screenshots show the traces in their colours where the plot puts them (pixels read back from the PNG).
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/json.hpp"
#include "cnccomp/io/report_json.hpp"
#include "cnccomp/io/svg_map.hpp"
#include "cnccomp/map_grid.hpp"
#include "app/report/html_report.hpp"
#include "cnccomp/error.hpp"
#include "app/report/polar_plot.hpp"
#include "app/report/report_format.hpp"
#include "test_browser.hpp"
#include "test_support.hpp"

namespace cnccomp {
using namespace cnccomp::io;
namespace {
namespace fs = std::filesystem;
using test::chromium, test::colourNear, test::countColour, test::near, test::readPng, test::rgb, test::screenshot;

const std::string kMachine = test::sourcePath("samples/machines/multitasking.xml");
const std::string kPlan = test::sourcePath("samples/plans/multitasking-six-circles.xml");
const std::string kTruth = test::sourcePath("samples/deviations/multitasking-truth.csv");

// ---- a run built by hand, for the plot tests ---------------------------------------------------------------------

app::report::RunSection sampleRun() {
    app::report::RunSection r;
    r.name = "C-X";
    r.test = "C-X";
    r.LB = 100;
    app::report::PolarPass ccw, cw;
    ccw.direction = +1;
    cw.direction = -1;
    for (int k = 0; k < 360; ++k) {
        const double a = k * kDeg;
        // An ellipse of ±8 µm (squareness) and 3 µm more on the CW pass; after compensation ±0.5 µm.
        ccw.angleDeg.push_back(k);
        ccw.before.push_back(8 * kUm * std::cos(2 * a));
        ccw.after.push_back(0.5 * kUm * std::sin(3 * a));
        cw.angleDeg.push_back(359 - k);
        cw.before.push_back(8 * kUm * std::cos(2 * (359 - k) * kDeg) + 3 * kUm);
        cw.after.push_back(0.5 * kUm * std::sin(3 * (359 - k) * kDeg) + 1.0 * kUm);
    }
    r.passes = {ccw, cw};
    return r;
}

TEST(ReportPolarPlot, TracesSitWhereTheScaleSaysInABrowserScreenshot) {
    const app::report::RunSection run = sampleRun();
    const app::report::PolarScale sc = app::report::polarScale(run);
    EXPECT_EQ(sc.ringUm, 5.0);  // 11 µm full scale → 5 µm rings (3 of them)
    EXPECT_EQ(sc.rings, 3);
    const std::string svg = app::report::renderPolarPlot(run, "p");
    EXPECT_EQ(svg.rfind("<svg", 0), 0u);
    for (const char* c : {app::report::kCcwBefore, app::report::kCwBefore, app::report::kCcwAfter, app::report::kCwAfter})
        EXPECT_NE(svg.find(c), std::string::npos) << c;
    EXPECT_NE(svg.find("5 µm per ring"), std::string::npos);
    if (!chromium()) GTEST_SKIP() << "Chromium is not installed (Debian package chromium, tools/deps.sh): the browser check is skipped";
    test::ScratchDir dir("polar-browser");
    test::writeText(dir.file("p.svg"), svg);
    const std::string log = screenshot(dir.file("p.svg"), dir.file("p.png"), static_cast<int>(app::report::kPolarWidth),
                                       static_cast<int>(app::report::kPolarHeight), dir);
    EXPECT_EQ(log.find("CONSOLE"), std::string::npos) << log;
    std::string why;
    const auto pic = readPng(dir.file("p.png"), why);
    if (!pic) GTEST_SKIP() << "cannot read the screenshot: " << why;
    // At 0°: CCW before at +8 µm, CW before at +11 µm, both outside the nominal circle on the right; at 90° the CCW
    // trace is 8 µm inside. The after traces stay within 1.5 µm of the nominal circle.
    const auto at = [&](double deg, double dl) { return app::report::polarPixel(sc, deg, dl); };
    for (const auto& [deg, dl, colour] : std::vector<std::tuple<double, double, const char*>>{
             {0, 8 * kUm, app::report::kCcwBefore}, {90, -8 * kUm, app::report::kCcwBefore}, {45, 0, app::report::kCcwBefore},
             {0, 11 * kUm, app::report::kCwBefore}, {90, -5 * kUm, app::report::kCwBefore}, {180, 11 * kUm, app::report::kCwBefore},
             {30, 0.5 * kUm, app::report::kCcwAfter}, {210, -0.5 * kUm + 1.0 * kUm, app::report::kCwAfter}}) {
        const app::report::PolarPixel p = at(deg, dl);
        EXPECT_TRUE(colourNear(*pic, p.x, p.y, colour)) << colour << " expected near " << deg << " deg, " << dl / kUm << " um";
    }
    // And not where nothing was drawn: the CCW trace is not on the nominal circle at 0°.
    const app::report::PolarPixel off = at(0, -8 * kUm);
    EXPECT_FALSE(colourNear(*pic, off.x, off.y, app::report::kCcwBefore, 2));
}

TEST(ReportMapSvg, ScaleFromZeroSharedClippedArrowsMicrometresAndZeroMessage) {
    const MachineModel& m = test::multitasking();
    const DeviationSet truth = readDeviationCsv(kTruth, m);
    MapRequest req{m, truth, parseGrid("X=-100:100:20 Y=-100:100:20 Z=0 B=0 C=0"), 100.0, {}, 1};
    const VolumetricMap map = computeMap(req);
    const MapPlane plane = parseMapPlane("XY");
    const double own = planeMaxError(map, plane) / kUm;
    ASSERT_GT(own, 1.0);
    SvgInfo info;
    info.title = "machine <A&B>";
    info.scaleMaxUm = 3 * own;  // shared with a worse map
    info.idPrefix = "m1";
    const std::string svg = renderMapSvg(map, m, plane, info);
    EXPECT_NE(svg.find("machine &lt;A&amp;B&gt;"), std::string::npos);
    EXPECT_NE(svg.find("|e| (µm)"), std::string::npos);
    EXPECT_EQ(svg.find(" um"), std::string::npos);
    EXPECT_NE(svg.find("X axis position (mm)"), std::string::npos);
    EXPECT_NE(svg.find("clip-path=\"url(#m1-frame)\""), std::string::npos);
    EXPECT_NE(svg.find("marker-end=\"url(#m1-head)\""), std::string::npos);
    // The colour bar starts at 0 and reaches the shared maximum.
    EXPECT_NE(svg.find(">0</text>"), std::string::npos);
    const double top = app::report::niceNumber(3 * own / 5) * std::ceil(3 * own / app::report::niceNumber(3 * own / 5) - 1e-9);
    EXPECT_NE(svg.find(fmt::format(">{:g}</text>", top)), std::string::npos) << top;
    // The cells use only the lower part of the scale: no yellow (the top colour) in any cell.
    EXPECT_NE(svg.find("#fde725"), std::string::npos);  // in the colour bar
    EXPECT_EQ(svg.find("fill=\"#fde725\" stroke"), std::string::npos);
    // Orientation mode: the coordinates are the tool tip in the workpiece frame.
    MapRequest ori{m, truth, parseGrid("X=-50:50:50 Y=-50:50:50 Z=300"), 100.0, Vec3(0, 0, 1), 1};
    EXPECT_NE(renderMapSvg(computeMap(ori), m, plane, {}).find("tool tip X in the workpiece frame (mm)"), std::string::npos);
    // All zero.
    const DeviationSet zero(m);
    MapRequest zr{m, zero, parseGrid("X=-100:100:20 Y=-100:100:20 Z=0 B=0 C=0"), 100.0, {}, 1};
    const std::string z = renderMapSvg(computeMap(zr), m, plane, {});
    EXPECT_NE(z.find("no error on this plane: |e| = 0 everywhere"), std::string::npos);
    EXPECT_NE(z.find("the error is zero on this whole plane"), std::string::npos);
    EXPECT_EQ(z.find("a plane axis is not"), std::string::npos);
}

TEST(ReportHtml, IdentifyWritesASelfContainedPageThatChromiumShows) {
    test::ScratchDir dir("report-html");
    const std::string traces = dir.file("traces");
    auto r = test::runCli("simulate --machine " + kMachine + " --plan " + kPlan + " --deviations " + kTruth + " --out " + traces +
                          " --noise-um 0.2 --seed 5");
    ASSERT_EQ(r.exitCode, 0) << r.out;
    r = test::runCli("identify --machine " + kMachine + " --plan " + kPlan + " --traces " + traces + " --out " +
                     dir.file("d.csv") + " --report " + dir.file("report.html") + " --report-controllers linuxcnc-pins,isg");
    ASSERT_EQ(r.exitCode, 0) << r.out;
    // Every file of the report.
    for (const char* f : {"report.html", "report.summary.json", "report-polar-B-X.svg", "report-polar-C-radial-RB2.svg",
                          "report-map-1.svg", "report-map-2.svg", "report-map-3.svg"})
        EXPECT_TRUE(fs::exists(dir.file(f))) << f;
    const std::string html = test::readText(dir.file("report.html"));
    // Self-contained: nothing fetched (the only URL is the SVG namespace), no script that runs.
    for (const char* bad : {"src=", "href=", "<link", "@import", "url(http", "<script>", "<script src"})
        EXPECT_EQ(html.find(bad), std::string::npos) << bad;
    size_t pos = 0;
    while ((pos = html.find("http", pos)) != std::string::npos) {
        EXPECT_EQ(html.compare(pos, 26, "http://www.w3.org/2000/svg"), 0) << html.substr(pos, 60);
        ++pos;
    }
    // The plots in the page are the SVG files.
    EXPECT_NE(html.find(test::readText(dir.file("report-polar-B-X.svg")).substr(0, 200)), std::string::npos);
    const Json j = readJsonFile(dir.file("report.summary.json"));
    EXPECT_EQ(j["runs"].array.size(), 6u);
    EXPECT_EQ(j["deviations"].array.size(), 13u);
    EXPECT_EQ(j["unidentified"].array.size(), 0u);
    EXPECT_EQ(j["maps"].array.size(), 3u);
    ASSERT_EQ(j["controllers"].array.size(), 2u);
    EXPECT_EQ(j["controllers"][0]["name"].string, "linuxcnc-pins");
    EXPECT_GT(j["controllers"][0]["not_compensated"].array.size(), 0u);  // LinuxCNC's tables cannot hold squareness
    EXPECT_LT(j["controllers"][1]["after_max_um"].num(), 0.1 * j["controllers"][1]["before_max_um"].num());  // ISG: all
    // Before vs after on every run: the compensation removes almost all of the circular deviation.
    for (const Json& run : j["runs"].array) {
        EXPECT_GT(run["before"]["G_um"].num(), 0.0) << run["name"].string;
        EXPECT_LT(run["after"]["G_um"].num(), 2.0) << run["name"].string;  // noise 0.2 µm: a few σ
        EXPECT_NEAR(run["rms_after_um"].num(), 0.2, 0.03) << run["name"].string;
    }
    // The radial deviation F before spans several µm on some run (the machine's eccentricities), after well below.
    double spanBefore = 0, spanAfter = 0;
    for (const Json& run : j["runs"].array) {
        spanBefore = std::max(spanBefore, run["before"]["F_max_um"].num() - run["before"]["F_min_um"].num());
        spanAfter = std::max(spanAfter, run["after"]["F_max_um"].num() - run["after"]["F_min_um"].num());
    }
    EXPECT_GT(spanBefore, 20.0);
    EXPECT_LT(spanAfter, 2.5);
    // The maps share one scale from 0 up to the worst of them.
    double worst = 0;
    for (const Json& mp : j["maps"].array) worst = std::max(worst, mp["plane_max_um"].num());
    EXPECT_NEAR(j["map_scale_max_um"].num(), worst, 1e-9);

    if (!chromium()) GTEST_SKIP() << "Chromium is not installed (Debian package chromium, tools/deps.sh): the browser check is skipped";
    const std::string log = screenshot(dir.file("report.html"), dir.file("page.png"), 1400, 2400, dir);
    EXPECT_EQ(log.find("CONSOLE"), std::string::npos) << log;
    std::string why;
    const auto pic = readPng(dir.file("page.png"), why);
    if (!pic) GTEST_SKIP() << "cannot read the screenshot: " << why;
    // The polar plots are on the page: the before traces (blue) in quantity, and each plot's blue pixels form a ring
    // (the bounding box of the first plot's trace is about as wide as it is high, with no blue at its centre).
    EXPECT_GT(countColour(*pic, app::report::kCcwBefore), 3000);
    EXPECT_GT(countColour(*pic, app::report::kCcwAfter), 3000);
    // The first plot's CCW trace: the connected set of its pixels (3 px neighbourhood: the after trace is drawn over
    // it where they cross) from the topmost one in the first column of plots.
    const int column = static_cast<int>(app::report::kPolarWidth) + 40;
    int sx = -1, sy = -1;
    for (int y = 0; y < pic->h && sy < 0; ++y)
        for (int x = 0; x < column; ++x)
            if (near(pic->at(x, y), rgb(app::report::kCcwBefore), 24)) {
                sx = x, sy = y;
                break;
            }
    ASSERT_GE(sy, 0);
    std::vector<char> seen(static_cast<size_t>(pic->w) * pic->h, 0);
    std::vector<std::pair<int, int>> todo{{sx, sy}};
    seen[static_cast<size_t>(sy) * pic->w + sx] = 1;
    int x0 = sx, x1 = sx, y0 = sy, y1 = sy;
    while (!todo.empty()) {
        const auto [x, y] = todo.back();
        todo.pop_back();
        x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
        for (int dy = -3; dy <= 3; ++dy)
            for (int dx = -3; dx <= 3; ++dx) {
                const int xx = x + dx, yy = y + dy;
                if (xx < 0 || yy < 0 || xx >= pic->w || yy >= pic->h) continue;
                char& v = seen[static_cast<size_t>(yy) * pic->w + xx];
                if (v || !near(pic->at(xx, yy), rgb(app::report::kCcwBefore), 60)) continue;
                v = 1;
                todo.emplace_back(xx, yy);
            }
    }
    ASSERT_GT(x1, x0);
    const double wBox = x1 - x0, hBox = y1 - y0;
    EXPECT_NEAR(wBox / hBox, 1.0, 0.15) << x0 << " " << x1 << " " << y0 << " " << y1;
    EXPECT_GT(wBox, 2 * (app::report::kPolarNominalPx - app::report::kPolarBandPx));  // within the scale rings
    EXPECT_LT(wBox, 2 * (app::report::kPolarNominalPx + app::report::kPolarBandPx));
    EXPECT_FALSE(colourNear(*pic, (x0 + x1) / 2.0, (y0 + y1) / 2.0, app::report::kCcwBefore, 20));
}

TEST(ReportHtml, NamesAreEscapedAndRunNamesMustBeFileNames) {
    app::report::ReportData d;
    d.title = "Machine <A&B> \"test\"";
    d.machine = "A&B";
    d.deviations.push_back({"EB0B", "bXB", "arcsec", true, 1, 0, 2});
    d.deviations.push_back({"EC0Y", "gXY", "arcsec", false});
    d.warnings.push_back("x < y & z");
    const app::report::ReportFiles f = app::report::reportFiles("o/r.html", d);
    const std::string html = app::report::formatHtmlReport(d, f, {});
    EXPECT_NE(html.find("<title>Machine &lt;A&amp;B&gt; &quot;test&quot;</title>"), std::string::npos);
    EXPECT_NE(html.find("x &lt; y &amp; z"), std::string::npos);
    EXPECT_EQ(html.substr(0, html.find("<script")).find("<A&B>"), std::string::npos);
    EXPECT_NE(html.find("Not identified (these measurements cannot tell them apart, or do not see them): EC0Y (gXY)"),
              std::string::npos);
    // The JSON summary inside the page cannot end the script element early.
    d.title = "</script><b>";
    const std::string json = app::report::formatReportSummaryJson(d, f);
    EXPECT_EQ(json.find("</script>"), std::string::npos);
    EXPECT_EQ(parseJson(json)["title"].string, "</script><b>");
    app::report::RunSection bad;
    bad.name = "../x";
    d.runs.push_back(bad);
    EXPECT_THROW(app::report::reportFiles("o/r.html", d), InputError);
}

}  // namespace
}  // namespace cnccomp
