// Import of laser positioning runs (io/laser_csv.hpp) and the ISO 230-2 table / JSON written from them
// (io/laser_report.hpp). Oracles: hand-made files whose readings are known by construction, and the sample file
// samples/laser/x-axis-iso230-2.csv whose generating model (20 um/m scale error, 3 um lost motion) is stated in it.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/laser_csv.hpp"
#include "cnccomp/io/laser_report.hpp"
#include "cnccomp/laser_positioning.hpp"
#include "test_support.hpp"

namespace cnccomp {
using namespace cnccomp::io;
namespace {

const std::string kSample = test::sourcePath("samples/laser/x-axis-iso230-2.csv");

/// Reading of run j (1-based) at target P (mm) in direction d (+1/−1), µm: known by construction.
double reading(int j, double P, int d) { return 0.01 * P + 0.5 * d + 0.1 * j; }

/// A file of `runs` runs over targets 0, 100, ..., 400, forward then reverse, with `sep` and labels.
std::string makeFile(int runs, char sep, const std::string& up, const std::string& down, bool decimalComma,
                     const std::string& header = "target_mm,run,direction,deviation_um", double scale = 1.0) {
    std::string h = header;
    for (char& c : h)
        if (c == ',') c = sep;
    std::string o = "# axis: Y\n# environment-compensated: no\n" + h + "\n";
    for (int j = 1; j <= runs; ++j)
        for (int d : {1, -1})
            for (int i = 0; i < 5; ++i) {
                const double P = d > 0 ? 100.0 * i : 100.0 * (4 - i);
                std::string v = fmt::format("{:.4f}", reading(j, P, d) * scale);
                if (decimalComma) v.replace(v.find('.'), 1, ",");
                o += fmt::format("{}{}{}{}{}{}{}\n", P, sep, j, sep, d > 0 ? up : down, sep, v);
            }
    return o;
}

TEST(LaserCsv, ReadsRunsByTargetRunAndDirection) {
    const LaserCsvFile f = parseLaserCsv(makeFile(5, ',', "+", "-", false), "l.csv");
    EXPECT_EQ(f.runs.axis, "Y");
    EXPECT_EQ(f.runs.source, "l.csv");
    EXPECT_TRUE(f.environmentStated);
    EXPECT_FALSE(f.runs.environmentCompensated);
    ASSERT_EQ(f.runs.targets.size(), 5u);
    ASSERT_EQ(f.runs.forward.size(), 5u);
    ASSERT_EQ(f.runs.reverse.size(), 5u);
    for (int j = 0; j < 5; ++j)
        for (int i = 0; i < 5; ++i) {
            EXPECT_NEAR(f.runs.forward[j][i], reading(j + 1, 100.0 * i, 1), 1e-12);
            EXPECT_NEAR(f.runs.reverse[j][i], reading(j + 1, 100.0 * i, -1), 1e-12);
        }
}

TEST(LaserCsv, BomSemicolonDecimalCommaWordLabelsMmAndOtherColumnNamesReadTheSame) {
    const LaserCsvFile a = parseLaserCsv(makeFile(5, ',', "+", "-", false), "a.csv");
    const std::string text = "\xEF\xBB\xBF" + makeFile(5, ';', "FWD", "rev", true, "pos,lauf,richtung,abw", 0.001);
    LaserCsvOptions o;
    o.targetColumn = "pos";
    o.runColumn = "lauf";
    o.directionColumn = "richtung";
    o.deviationColumn = "abw";
    o.deviationUnit = "mm";
    const LaserCsvFile b = parseLaserCsv(text, "b.csv", o);
    ASSERT_EQ(b.runs.forward.size(), 5u);
    for (int j = 0; j < 5; ++j)
        for (int i = 0; i < 5; ++i) {
            EXPECT_NEAR(b.runs.forward[j][i], a.runs.forward[j][i], 1e-9);
            EXPECT_NEAR(b.runs.reverse[j][i], a.runs.reverse[j][i], 1e-9);
        }
    const std::string words = makeFile(5, ',', "forward", "Reverse", false);
    EXPECT_EQ(parseLaserCsv(words, "w.csv").runs.reverse.size(), 5u);
}

void expectError(const std::string& text, const std::string& part, const LaserCsvOptions& o = {}) {
    try {
        const LaserCsvFile f = parseLaserCsv(text, "bad.csv", o);
        evaluateLaserPositioning(f.runs);
        ADD_FAILURE() << "no error; expected one with '" << part << "'";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
        EXPECT_EQ(std::string(e.what()).rfind("bad.csv", 0), 0u) << e.what();
    }
}

TEST(LaserCsv, BadInputNamesFileLineAndWhatWasExpected) {
    const std::string good = makeFile(5, ',', "+", "-", false);
    // Header is line 3, the first reading line 4: forward of run 1 at 0, 100, ..., 400 (lines 4..8), reverse 9..13.
    std::string oneDirection;
    for (const std::string& l : {std::string("# axis: X"), std::string("target_mm,run,direction,deviation_um")})
        oneDirection += l + "\n";
    for (int j = 1; j <= 5; ++j)
        for (int i = 0; i < 5; ++i) oneDirection += fmt::format("{},{},+,0.5\n", 100 * i, j);
    expectError(oneDirection, "one direction only");

    std::string missing = good;
    missing.erase(missing.find("100,3,-,"), missing.find('\n', missing.find("100,3,-,")) - missing.find("100,3,-,") + 1);
    expectError(missing, "run 3 reverse (from this line) has no reading at target 100 mm");
    expectError(missing, "bad.csv:");

    std::string nonNumber = good;
    nonNumber.replace(nonNumber.find("200,1,+,") + 8, 1, "x");
    expectError(nonNumber, "bad.csv:6: deviation");

    std::string direction = good;
    direction.replace(direction.find("300,1,+"), 7, "300,1,up");
    expectError(direction, "bad.csv:7: direction 'up'; expected + or -");

    std::string twice = good;
    twice.replace(twice.find("100,1,+"), 7, "0,1,+");
    expectError(twice, "bad.csv:5: run 1 forward has a second reading at target 0 mm");

    expectError(makeFile(4, ',', "+", "-", false), "4 runs in each direction; ISO 230-2 4.3.2 asks for at least 5");

    std::string env = good;
    env.replace(env.find("compensated: no"), 15, "compensated: maybe");
    expectError(env, "bad.csv:2: environment-compensated: 'maybe'; expected yes or no");

    LaserCsvOptions other;
    other.axis = "Z";
    expectError(good, "bad.csv:1: the file is of axis Y but axis Z was asked for", other);
    expectError(good.substr(good.find('\n') + 1), "no axis name");
    LaserCsvOptions unit;
    unit.deviationUnit = "in";
    expectError(good, "deviation unit 'in'; expected um or mm", unit);
    expectError(good, "no column 'deviation_mm'", [] {
        LaserCsvOptions mm;
        mm.deviationUnit = "mm";
        return mm;
    }());
}

TEST(LaserCsv, ReadFromDiskNamesTheFileInTheEvaluationsErrors) {
    test::ScratchDir dir("laser-csv");
    test::writeText(dir.file("few.csv"), makeFile(3, ',', "+", "-", false));
    try {
        evaluateLaserPositioning(readLaserCsv(dir.file("few.csv")).runs);
        ADD_FAILURE() << "3 runs accepted";
    } catch (const InputError& e) {
        EXPECT_EQ(e.file(), dir.file("few.csv"));
    }
}

// The sample: its generating model is known (file comments), so the figures are bounded by construction: the mean
// reversal near −3 um, the forward means rise by about 20 um/m × 500 mm = 10 um, and its table and JSON carry them.
TEST(LaserCsv, TheSampleGivesTheFiguresOfItsModel) {
    const LaserCsvFile f = readLaserCsv(kSample);
    EXPECT_TRUE(f.runs.environmentCompensated);
    const LaserPositioningResult r = evaluateLaserPositioning(f.runs);
    ASSERT_EQ(r.targets.size(), 11u);
    EXPECT_EQ(r.runs, 5);
    EXPECT_NEAR(r.meanReversal, -3.0, 0.4);
    EXPECT_NEAR(r.targets.back().meanForward - r.targets.front().meanForward, 10.0, 0.6);
    EXPECT_NEAR(r.EForward, 10.0, 0.8);
    EXPECT_GT(r.E, r.EForward);
    const std::string table = formatLaserTable(r, f.environmentStated);
    EXPECT_NE(table.find("environment compensation: done (stated in the file)"), std::string::npos) << table;
    EXPECT_NE(table.find(fmt::format("B-bar = {:.3f} um", r.meanReversal)), std::string::npos) << table;
    const std::string json = formatLaserJson(r, f.environmentStated, kSample);
    EXPECT_NE(json.find(fmt::format("\"B_mean_um\": {:.6g}", r.meanReversal)), std::string::npos) << json;
    EXPECT_NE(json.find(fmt::format("\"M_um\": {:.6g}", r.M)), std::string::npos) << json;
    EXPECT_NE(json.find("\"environment_compensated\": true"), std::string::npos);
}

}  // namespace
}  // namespace cnccomp
