// `cnccomp verify --report r.html`: the page of a verification end to end. Its numbers are checked against the raw
// samples verify writes to --json (F max / min, mean radius and span recomputed here from the ΔL arrays; H = 0 where
// the geometric machine reads the same CW and CCW), the compensation's coverage against the header of the files emit
// wrote (read here as text), the values of the deviations left against the truth file; the page in headless Chromium
// (no console errors) and the traces of a polar plot where its scale puts them (pixels of a screenshot); all or
// nothing with --json; the options checked.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>

#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/json.hpp"
#include "cnccomp/io/report_json.hpp"
#include "app/report/polar_plot.hpp"
#include "test_browser.hpp"
#include "test_deviation_text.hpp"
#include "test_support.hpp"

namespace cnccomp {
using namespace cnccomp::io;
namespace {
namespace fs = std::filesystem;

const std::string kMachine = test::sourcePath("samples/machines/multitasking.xml");
const std::string kPlan = test::sourcePath("samples/plans/multitasking-six-circles.xml");
const std::string kTruth = test::sourcePath("samples/deviations/multitasking-truth.csv");

/// emit --controller NAME with the truth set into dir/NAME, then verify through it on the true machine with --report
/// dir/NAME-report/report.html and --json dir/NAME-report/verify.json (plus `extra` options).
test::CliResult emitAndVerify(const test::ScratchDir& dir, const std::string& controller, const std::string& extra = "") {
    auto r = test::runCli("emit --controller " + controller + " --machine " + kMachine + " --deviations " + kTruth + " --out " +
                          dir.file(controller));
    if (r.exitCode != 0) return r;
    return test::runCli("verify --machine " + kMachine + " --plan " + kPlan + " --compensation " + dir.file(controller) +
                        " --truth " + kTruth + " --report " + dir.file(controller + "-report/report.html") + " --json " +
                        dir.file(controller + "-report/verify.json") + " " + extra);
}

/// The deviation names of a list in a header comment ("# compensated:" / "# NOT compensated:", one "#   NAME  why"
/// line each), read as text: an oracle independent of verify's reader.
std::vector<std::string> headerList(const std::string& text, const std::string& title) {
    std::vector<std::string> out;
    std::istringstream in(text);
    std::string line;
    bool inList = false;
    while (std::getline(in, line)) {
        if (line == "# " + title) {
            inList = true;
        } else if (inList) {
            if (line.rfind("#   ", 0) != 0) break;
            std::istringstream w(line.substr(4));
            std::string name;
            w >> name;
            out.push_back(name);
        }
    }
    return out;
}

std::vector<std::string> names(const Json& array, const char* key = nullptr) {
    std::vector<std::string> out;
    for (const Json& v : array.array) out.push_back(key ? v[key].string : v.string);
    return out;
}

TEST(VerifyReport, NumbersOfThePageAreThoseOfTheSamplesAndTheFiles) {
    test::ScratchDir dir("verify-report");
    // LinuxCNC's pins-and-tables route: a controller that leaves deviations (its component route leaves none).
    const auto r = emitAndVerify(dir, "linuxcnc-pins");
    const std::string base = dir.file("linuxcnc-pins-report/");
    ASSERT_TRUE(fs::exists(base + "verify.json")) << r.out;
    // No gate given: exit status 1 only where the files make the machine worse than none (verify.hpp VerifyWorse).
    EXPECT_EQ(r.exitCode, readJsonFile(base + "verify.json")["makes_machine_worse"].boolean ? 1 : 0) << r.out;
    EXPECT_NE(r.out.find("report -> "), std::string::npos);
    for (const char* f : {"report.html", "report.summary.json", "report-polar-B-X.svg", "report-polar-C-radial-RB2.svg",
                          "report-map-1.svg", "report-map-2.svg", "verify.json"})
        EXPECT_TRUE(fs::exists(base + f)) << f;
    const Json s = readJsonFile(base + "report.summary.json"), v = readJsonFile(base + "verify.json");
    ASSERT_EQ(s["runs"].array.size(), 6u);
    ASSERT_EQ(v["runs"].array.size(), 6u);
    for (size_t i = 0; i < 6; ++i) {
        const Json& run = s["runs"][i];
        const Json& raw = v["runs"][i];
        ASSERT_EQ(run["name"].string, raw["name"].string);
        EXPECT_EQ(names(run["passes"]), (std::vector<std::string>{"cw", "ccw"}));  // as the test programs run them
        // F max / F min over both passes and the span of each pass, recomputed from the raw ΔL samples.
        for (const char* when : {"before", "after"}) {
            double hi = -1e9, lo = 1e9, sum = 0;
            size_t n = 0;
            for (const Json& p : raw["passes"].array) {
                double phi = -1e9, plo = 1e9;
                for (const Json& x : p[std::string("dL_") + when + "_um"].array) {
                    phi = std::max(phi, x.num()), plo = std::min(plo, x.num());
                    sum += x.num();
                    ++n;
                }
                hi = std::max(hi, phi), lo = std::min(lo, plo);
                const auto span = std::find_if(s["spans"].array.begin(), s["spans"].array.end(), [&](const Json& x) {
                    return x["run"].string == run["name"].string && x["pass"].string == p["direction"].string;
                });
                ASSERT_NE(span, s["spans"].array.end());
                EXPECT_NEAR((*span)[std::string(when) + "_um"].num(), phi - plo, 1e-6) << run["name"].string << " " << when;
            }
            EXPECT_NEAR(run[when]["F_max_um"].num(), hi, 1e-6) << run["name"].string;
            EXPECT_NEAR(run[when]["F_min_um"].num(), lo, 1e-6) << run["name"].string;
            // Mean radius: LB + mean ΔL of a uniformly sampled full turn, to second order (|e|²/LB < 0.1 µm here).
            EXPECT_NEAR(run[when]["mean_radius_mm"].num(), 100.0 + sum / static_cast<double>(n) * 1e-3, 1e-4) << run["name"].string;
            // The geometric machine reads the same CW and CCW: no hysteresis.
            EXPECT_NEAR(run[when]["H_um"].num(), 0.0, 1e-6) << run["name"].string;
        }
    }
    EXPECT_EQ(s["spans"].array.size(), 12u);
    // The compensation: the files, what their header says they take and leave, the values left (from the truth file),
    // the residual and the volumetric figures verify reports.
    ASSERT_EQ(s["controllers"].array.size(), 1u);
    const Json& c = s["controllers"][0];
    EXPECT_EQ(c["name"].string, "linuxcnc-pins");
    const std::vector<std::string> files = names(c["files"]);
    EXPECT_NE(std::find(files.begin(), files.end(), (fs::path(dir.file("linuxcnc-pins")) / "cnccomp.ini").string()), files.end());
    const std::string ini = test::readText(dir.file("linuxcnc-pins/cnccomp.ini"));
    EXPECT_EQ(names(c["compensated"]), headerList(ini, "compensated:"));
    EXPECT_EQ(names(c["not_compensated"]), headerList(ini, "NOT compensated:"));
    EXPECT_EQ(c["not_compensated"].array.size(), 10u);
    // The values left as the truth file writes them (its text, not the deviation vector): the ISO value under the ISO
    // name, the paper's value under the alias.
    const auto truthRows = test::deviationRowsAsWritten(kTruth);
    for (const Json& left : c["remaining"].array) {
        const std::string name = left["deviation"].string;
        ASSERT_TRUE(truthRows.count(name)) << name;
        const test::DeviationRowText& row = truthRows.at(name);
        EXPECT_EQ(left["unit"].string, row.unit) << name;
        EXPECT_NEAR(left["value"].num(), row.value, 1e-9) << name;
        EXPECT_EQ(left["alias"].string, row.alias) << name;
        EXPECT_NEAR(left["alias_value"].num(), row.aliasValue, 1e-9) << name;
        EXPECT_FALSE(left["reason"].string.empty());
    }
    EXPECT_NEAR(c["span_after_um"].num(), v["residual_um"].num(), 1e-6);  // the summary's 9 significant digits
    EXPECT_NEAR(c["span_before_um"].num(), v["residual_before_um"].num(), 1e-6);
    EXPECT_NEAR(c["before_max_um"].num(), v["volumetric"]["max_before_um"].num(), 1e-6);
    EXPECT_NEAR(c["after_max_um"].num(), v["volumetric"]["max_after_um"].num(), 1e-6);
    EXPECT_GT(c["span_after_um"].num(), 10.0);  // LinuxCNC cannot hold the squareness and tilts of this machine
    // Maps before and after on one scale from 0 up to the worse of them; LinuxCNC leaves an error on the plane.
    ASSERT_EQ(s["maps"].array.size(), 2u);
    EXPECT_NEAR(s["map_scale_max_um"].num(), std::max(s["maps"][0]["plane_max_um"].num(), s["maps"][1]["plane_max_um"].num()), 1e-9);
    EXPECT_GT(s["maps"][1]["plane_max_um"].num(), 1.0);
    // The page carries the reasons and the values of what is left.
    const std::string html = test::readText(base + "report.html");
    EXPECT_NE(html.find("Deviations linuxcnc-pins leaves, and why"), std::string::npos);
    EXPECT_NE(html.find("LinuxCNC has no cross-axis compensation"), std::string::npos);
    for (const char* bad : {"src=", "href=", "<link", "@import", "<script>"}) EXPECT_EQ(html.find(bad), std::string::npos) << bad;
}

/// A polar plot's run rebuilt from the raw samples of verify.json, for its scale.
app::report::RunSection runFromJson(const Json& raw) {
    app::report::RunSection r;
    r.name = raw["name"].string;
    r.LB = raw["LB_mm"].num();
    for (const Json& p : raw["passes"].array) {
        app::report::PolarPass pp;
        pp.direction = p["direction"].string == "CCW" ? +1 : -1;
        for (const Json& a : p["angle_deg"].array) pp.angleDeg.push_back(a.num());
        for (const Json& x : p["dL_before_um"].array) pp.before.push_back(x.num() * kUm);
        for (const Json& x : p["dL_after_um"].array) pp.after.push_back(x.num() * kUm);
        r.passes.push_back(std::move(pp));
    }
    return r;
}

TEST(VerifyReport, ChromiumShowsThePageAndTheTracesBeforeAndAfterWhereTheScalePutsThem) {
    test::ScratchDir dir("verify-report-browser");
    const auto r = emitAndVerify(dir, "isg");  // ISG's table takes every deviation of this machine: after ≈ 0
    ASSERT_EQ(r.exitCode, 0) << r.out;
    const std::string base = dir.file("isg-report/");
    const Json v = readJsonFile(base + "verify.json");
    EXPECT_LT(v["residual_um"].num(), 0.1);
    if (!test::chromium()) GTEST_SKIP() << "Chromium is not installed (Debian package chromium, tools/deps.sh): the browser check is skipped";
    const std::string log = test::screenshot(base + "report.html", dir.file("page.png"), 1400, 2400, dir);
    EXPECT_EQ(log.find("CONSOLE"), std::string::npos) << log;
    std::string why;
    const auto page = test::readPng(dir.file("page.png"), why);
    if (!page) GTEST_SKIP() << "cannot read the screenshot: " << why;
    EXPECT_GT(test::countColour(*page, app::report::kCcwBefore), 2000);
    EXPECT_GT(test::countColour(*page, app::report::kCcwAfter), 2000);
    // The C-radial plot on its own: before (CW wide underneath, CCW on top) and after at the pixels the scale gives
    // for the samples' ΔL, every 30°.
    const Json* raw = nullptr;
    for (const Json& run : v["runs"].array)
        if (run["name"].string == "C-radial") raw = &run;
    ASSERT_NE(raw, nullptr);
    const app::report::RunSection run = runFromJson(*raw);
    const app::report::PolarScale sc = app::report::polarScale(run);
    test::screenshot(base + "report-polar-C-radial.svg", dir.file("polar.png"), static_cast<int>(app::report::kPolarWidth),
                     static_cast<int>(app::report::kPolarHeight), dir);
    const auto pic = test::readPng(dir.file("polar.png"), why);
    if (!pic) GTEST_SKIP() << "cannot read the screenshot: " << why;
    int checked = 0;
    for (const app::report::PolarPass& p : run.passes) {
        if (p.direction < 0) continue;  // the CCW pass is on top; the CW pass is the same here (checked above: H = 0)
        for (size_t i = 0; i < p.angleDeg.size(); i += 30) {
            const app::report::PolarPixel b = app::report::polarPixel(sc, p.angleDeg[i], p.before[i]);
            const app::report::PolarPixel a = app::report::polarPixel(sc, p.angleDeg[i], p.after[i]);
            // CCW after is drawn last, on top of everything.
            EXPECT_TRUE(test::colourNear(*pic, a.x, a.y, app::report::kCcwAfter, 2)) << "CCW after at " << p.angleDeg[i] << " deg";
            if (std::hypot(a.x - b.x, a.y - b.y) < 15) continue;  // where they meet, after covers before
            EXPECT_TRUE(test::colourNear(*pic, b.x, b.y, app::report::kCcwBefore, 2)) << "CCW before at " << p.angleDeg[i] << " deg";
            EXPECT_TRUE(test::colourNear(*pic, b.x, b.y, app::report::kCwBefore, 4)) << "CW before at " << p.angleDeg[i] << " deg";
            EXPECT_TRUE(test::colourNear(*pic, a.x, a.y, app::report::kCwAfter, 4)) << "CW after at " << p.angleDeg[i] << " deg";
            // Where before and after are far apart, neither colour sits at the other's place.
            EXPECT_FALSE(test::colourNear(*pic, b.x, b.y, app::report::kCcwAfter, 2)) << p.angleDeg[i];
            EXPECT_FALSE(test::colourNear(*pic, a.x, a.y, app::report::kCcwBefore, 2)) << p.angleDeg[i];
            ++checked;
        }
    }
    EXPECT_GE(checked, 6);  // the C-radial run's 60 µm eccentricity puts before and after far apart on most of the turn
}

TEST(VerifyReport, CorrectedProgramsHaveNoMapAndTheIdealCompensationListsItsSet) {
    test::ScratchDir dir("verify-report-corrected");
    auto r = test::runCli("testprog --machine " + kMachine + " --plan " + kPlan + " --dialect linuxcnc --out " + dir.file("tp"));
    ASSERT_EQ(r.exitCode, 0) << r.out;
    fs::create_directories(dir.file("corrected"));
    for (const auto& e : fs::directory_iterator(dir.file("tp"))) {
        if (e.path().extension() != ".ngc") continue;
        const std::string text = test::readText(e.path().string());
        const size_t at = text.find("cnccomp correct --tool-length ");
        ASSERT_NE(at, std::string::npos);
        const std::string length = text.substr(at + 30, text.find(')', at) - at - 30);
        r = test::runCli("correct --machine " + kMachine + " --deviations " + kTruth + " --in " + e.path().string() + " --out " +
                         dir.file("corrected/" + e.path().filename().string()) + " --tool-length " + length);
        ASSERT_EQ(r.exitCode, 0) << r.out;
    }
    r = test::runCli("verify --machine " + kMachine + " --plan " + kPlan + " --compensation " + dir.file("corrected") +
                     " --truth " + kTruth + " --report " + dir.file("c/report.html"));
    ASSERT_EQ(r.exitCode, 0) << r.out;
    Json s = readJsonFile(dir.file("c/report.summary.json"));
    EXPECT_EQ(s["maps"].array.size(), 0u);
    EXPECT_FALSE(fs::exists(dir.file("c/report-map-1.svg")));
    bool said = false;
    for (const Json& f : s["facts"].array) said = said || f[1].string.find("compensates its own poses only") != std::string::npos;
    EXPECT_TRUE(said);
    EXPECT_EQ(s["controllers"][0]["name"].string, "corrected test programs");
    EXPECT_EQ(s["controllers"][0]["files"].array.size(), 6u);
    EXPECT_LT(s["controllers"][0]["span_after_um"].num(), 0.1);
    // Ideal compensation with the truth itself: every deviation of the set listed as compensated, nothing left.
    r = test::runCli("verify --machine " + kMachine + " --plan " + kPlan + " --compensation " + kTruth + " --truth " + kTruth +
                     " --report " + dir.file("i/report.html"));
    ASSERT_EQ(r.exitCode, 0) << r.out;
    s = readJsonFile(dir.file("i/report.summary.json"));
    EXPECT_EQ(s["controllers"][0]["name"].string, "ideal");
    EXPECT_EQ(s["controllers"][0]["compensated"].array.size(), 13u);
    EXPECT_EQ(s["controllers"][0]["not_compensated"].array.size(), 0u);
    for (const Json& run : s["runs"].array) EXPECT_LT(run["after"]["F_max_um"].num() - run["after"]["F_min_um"].num(), 0.01);
}

TEST(VerifyReport, AFailedGateStillWritesTheReportAndAFailedCommandWritesNothing) {
    test::ScratchDir dir("verify-report-gate");
    auto r = emitAndVerify(dir, "linuxcnc-pins", "--max-residual-um 1");
    EXPECT_EQ(r.exitCode, 1) << r.out;
    const Json s = readJsonFile(dir.file("linuxcnc-pins-report/report.summary.json"));
    bool failed = false;
    for (const Json& f : s["facts"].array) failed = failed || (f[0].string == "gate" && f[1].string.find("FAILED") != std::string::npos);
    EXPECT_TRUE(failed);
    EXPECT_FALSE(readJsonFile(dir.file("linuxcnc-pins-report/verify.json"))["passed"].boolean);
    // --json names a folder: nothing at all is written, not even the report's folder.
    fs::create_directories(dir.file("taken"));
    r = test::runCli("verify --machine " + kMachine + " --plan " + kPlan + " --compensation " + dir.file("linuxcnc-pins") + " --truth " +
                     kTruth + " --report " + dir.file("new/report.html") + " --json " + dir.file("taken"));
    EXPECT_EQ(r.exitCode, 2) << r.out;
    EXPECT_FALSE(fs::exists(dir.file("new"))) << r.out;
    // A report never overwrites an input: here the controller's own file.
    r = test::runCli("verify --machine " + kMachine + " --plan " + kPlan + " --compensation " + dir.file("linuxcnc-pins") + " --truth " +
                     kTruth + " --report " + dir.file("x/r.html") + " --json " + dir.file("linuxcnc-pins/cnccomp.ini"));
    EXPECT_EQ(r.exitCode, 2) << r.out;
    EXPECT_NE(test::readText(dir.file("linuxcnc-pins/cnccomp.ini")).find("[KINS]"), std::string::npos);
    EXPECT_FALSE(fs::exists(dir.file("x")));
}

TEST(VerifyReport, AWorseCompensationShowsARedBannerAtTheTopOfThePage) {
    // Every value of the truth with the wrong sign: the compensation doubles the errors. The page opens with the red
    // banner (its text in the summary's alarms), whatever the gates; headless Chromium shows it at the top.
    test::ScratchDir dir("verify-report-worse");
    std::string flipped = "# cnccomp-deviations/2: location errors under ISO 230-1 names are ISO values (iso_names.hpp)\nname,alias,value,unit\n";
    for (const auto& [name, row] : test::deviationRowsAsWritten(kTruth))
        flipped += name + ",," + std::to_string(-row.value) + "," + row.unit + "\n";
    test::writeText(dir.file("flipped.csv"), flipped);
    const auto r = test::runCli("verify --machine " + kMachine + " --plan " + kPlan + " --compensation " + dir.file("flipped.csv") +
                                " --truth " + kTruth + " --report " + dir.file("w/report.html"));
    EXPECT_EQ(r.exitCode, 1) << r.out;
    const Json s = readJsonFile(dir.file("w/report.summary.json"));
    ASSERT_EQ(s["alarms"].array.size(), 1u);
    EXPECT_EQ(s["alarms"][0].string.rfind("COMPENSATION MAKES THE MACHINE WORSE", 0), 0u);
    const std::string html = test::readText(dir.file("w/report.html"));
    EXPECT_LT(html.find("class=\"alarm\""), html.find("<h1>"));
    if (!test::chromium()) GTEST_SKIP() << "Chromium is not installed (Debian package chromium, tools/deps.sh): the browser check is skipped";
    const std::string log = test::screenshot(dir.file("w/report.html"), dir.file("top.png"), 1400, 300, dir);
    EXPECT_EQ(log.find("CONSOLE"), std::string::npos) << log;
    std::string why;
    const auto pic = test::readPng(dir.file("top.png"), why);
    if (!pic) GTEST_SKIP() << "cannot read the screenshot: " << why;
    // The banner: #c00000 across the page's width (1352 px inside the margins, less its white text) and over 40 px high.
    EXPECT_GT(test::countColour(*pic, "#c00000"), 1000 * 40);
    // And an ideal compensation's page has none.
    const auto ok = test::runCli("verify --machine " + kMachine + " --plan " + kPlan + " --compensation " + kTruth + " --truth " +
                                 kTruth + " --report " + dir.file("ok/report.html"));
    ASSERT_EQ(ok.exitCode, 0) << ok.out;
    EXPECT_EQ(test::readText(dir.file("ok/report.html")).find("class=\"alarm\""), std::string::npos);
    test::screenshot(dir.file("ok/report.html"), dir.file("ok.png"), 1400, 300, dir);
    const auto okPic = test::readPng(dir.file("ok.png"), why);
    if (!okPic) GTEST_SKIP() << "cannot read the screenshot: " << why;
    EXPECT_LT(test::countColour(*okPic, "#c00000"), 100);
}

TEST(VerifyReport, OptionsAreChecked) {
    test::ScratchDir dir("verify-report-options");
    const std::string base = "verify --machine " + kMachine + " --plan " + kPlan + " --compensation " + kTruth + " --truth " + kTruth;
    auto r = test::runCli(base + " --report " + dir.file("r.txt"));
    EXPECT_EQ(r.exitCode, 2) << r.out;
    EXPECT_NE(r.out.find("HTML"), std::string::npos) << r.out;
    r = test::runCli(base + " --report-grid \"X=0\"");
    EXPECT_EQ(r.exitCode, 2) << r.out;
    r = test::runCli(base + " --report " + dir.file("r.html") + " --json " + dir.file("r.html"));
    EXPECT_EQ(r.exitCode, 2) << r.out;
    r = test::runCli(base + " --report " + dir.file("r.html") + " --report-plane QQ");
    EXPECT_EQ(r.exitCode, 2) << r.out;
    EXPECT_FALSE(fs::exists(dir.file("r.html")));
}

}  // namespace
}  // namespace cnccomp
