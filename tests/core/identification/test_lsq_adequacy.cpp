// Model adequacy: after every least-squares fit the residual is tested against the noise the data
// can have. The case of the issue: a DBB5 B/C plan on a machine whose C table has error motions of 4–6 µm / 4–6″,
// identified with the default eleven location and squareness errors — the fit absorbs the missing error motions into
// the squareness and C's tilt, so the values are wrong and, before this test, the report said nothing. Oracles: the
// simulator's known truth (round trip), and printed quantiles of the F / χ² distributions for the test's threshold.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/identification/adequacy.hpp"
#include "cnccomp/identification/dbb5_location_errors.hpp"
#include "cnccomp/identification/dbb5_observation.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "test_dbb5_support.hpp"
#include "test_support.hpp"

namespace cnccomp {
using namespace cnccomp::identification;
using namespace cnccomp::io;
using namespace cnccomp::measurement;
namespace {

const std::string kComponentsTruth = "samples/deviations/dbb5-table-table-bc-components-truth.csv";

DeviationSet componentsTruth() { return readDeviationCsv(test::sourcePath(kComponentsTruth), test::tableTableBc()); }

using test::simulateBc;

std::vector<int> eleven() {
    std::vector<int> d = dbb5LocationDeviations(test::tableTableBc(), {});
    std::sort(d.begin(), d.end());
    return d;
}

const ParameterEstimate& param(const IdentificationReport& r, const std::string& name) {
    const int i = r.find(name);
    if (i < 0) throw ModelError("no parameter " + name);
    return r.parameters[static_cast<size_t>(i)];
}

// Oracles: printed quantiles χ²(0.999; 10) = 29.588 (so F(10, ∞) = 2.9588) and F(0.99; 5, 10) = 5.636 (standard χ² and
// F tables, e.g. NIST/SEMATECH e-Handbook 1.3.6.7.4 and 1.3.6.7.2); F(0.999; 20, 40) = 3.145, computed independently from
// the regularized incomplete beta function (continued fraction of Numerical Recipes, section 6.4) in Python.
TEST(LsqAdequacy, FQuantileMatchesPrintedTables) {
    EXPECT_NEAR(fQuantile(0.999, 10, 1e9), 2.9588, 0.03);
    EXPECT_NEAR(fQuantile(0.99, 5, 10), 5.636, 0.15);
    EXPECT_NEAR(fQuantile(0.999, 20, 40), 3.145, 0.03);
}

// The case: C error motions, default eleven errors. The test must fire, name C's component errors and the option
// that adds them, come first among the warnings, and widen the intervals until they hold the truth.
TEST(LsqAdequacy, Dbb5WithMissingComponentErrorsOfCDoesNotFit) {
    const DeviationSet truth = componentsTruth();
    const Observations obs = simulateBc(truth, 0.2, 7);
    IdentifyOptions o;
    o.deviations = eleven();
    const IdentificationResult res = identify(test::tableTableBc(), obs, o);
    const IdentificationReport& r = res.report;
    const Adequacy& a = r.adequacy;
    ASSERT_TRUE(a.tested);
    EXPECT_FALSE(a.fits);
    EXPECT_GT(a.statistic, a.threshold);
    ASSERT_FALSE(r.warnings.empty());
    EXPECT_EQ(r.warnings.front(), a.message);
    EXPECT_EQ(a.message.rfind("the model does not fit the data", 0), 0u) << a.message;
    ASSERT_FALSE(a.suspected.empty());
    EXPECT_NE(a.suspected.front().find("of C: EXC EYC EZC EAC EBC ECC"), std::string::npos) << a.suspected.front();
    EXPECT_NE(a.option.find("--params all"), std::string::npos) << a.option;
    // The C runs fail with a pattern of orders 1–6; the linear circles do not point at C.
    for (const RunAdequacy& ra : a.runs)
        if (ra.run == "C-X-low" || ra.run == "C-Y-high") {
            EXPECT_FALSE(ra.fits) << ra.run;
            EXPECT_GT(ra.harmonicShare, 0.5) << ra.run;
            EXPECT_EQ(ra.noiseSource, "successive differences");
        }
    // Honest intervals: they hold the truth of the squareness and C's tilt that the fit got wrong.
    EXPECT_GT(a.inflation, 1.0);
    for (const char* n : {"EB0Z", "EC0Y", "EB0C", "EA0C", "EA0Z"}) {
        const ParameterEstimate& p = param(r, n);
        const double t = truth.isoValue(truth.require(n));
        EXPECT_LE(p.lower95, t) << n << " " << p.value / kArcsec << " truth " << t / kArcsec;
        EXPECT_GE(p.upper95, t) << n << " " << p.value / kArcsec << " truth " << t / kArcsec;
    }
}

// No false alarm: the same plan without component errors, 0.2 µm noise, over several seeds.
TEST(LsqAdequacy, Dbb5LocationErrorsOnlyFit) {
    for (unsigned seed = 1; seed <= 5; ++seed) {
        const Observations obs = simulateBc(test::dbb5TruthBc(), 0.2, seed);
        IdentifyOptions o;
        o.deviations = eleven();
        const IdentificationResult res = identify(test::tableTableBc(), obs, o);
        EXPECT_TRUE(res.report.adequacy.tested);
        EXPECT_TRUE(res.report.adequacy.fits) << seed << ": " << res.report.adequacy.message;
        EXPECT_EQ(res.report.adequacy.inflation, 1.0);
    }
}

// With the component errors of C among the unknowns the model fits, and the squareness is the truth.
TEST(LsqAdequacy, Dbb5WithComponentErrorsEstimatedFits) {
    const DeviationSet truth = componentsTruth();
    const Observations obs = simulateBc(truth, 0.2, 7);
    const IdentificationResult res = identify(test::tableTableBc(), obs, {});
    EXPECT_TRUE(res.report.adequacy.fits) << res.report.adequacy.message;
    for (const char* n : {"EB0Z", "EC0Y", "EA0Z"})
        EXPECT_NEAR(res.deviations.isoValue(truth.require(n)), truth.isoValue(truth.require(n)), 0.5 * kArcsec) << n;
}

// A stated instrument noise far below what the data show makes every run fail; the plan carries it as noise-um.
TEST(LsqAdequacy, StatedNoiseIsUsedAndReadFromThePlan) {
    const Observations obs = simulateBc(test::dbb5TruthBc(), 0.2, 3);
    IdentifyOptions o;
    o.deviations = eleven();
    o.statedNoise = 0.2 * kUm;
    const IdentificationResult fine = identify(test::tableTableBc(), obs, o);
    EXPECT_TRUE(fine.report.adequacy.fits) << fine.report.adequacy.message;
    ASSERT_FALSE(fine.report.adequacy.runs.empty());
    EXPECT_EQ(fine.report.adequacy.runs.front().noiseSource, "stated");
    o.statedNoise = 0.05 * kUm;
    EXPECT_FALSE(identify(test::tableTableBc(), obs, o).report.adequacy.fits);

    test::ScratchDir dir("adequacy-plan");
    MeasurementPlan p = test::dbb5PlanBc();
    p.noiseUm = 0.25;
    test::writeText(dir.file("p.xml"), formatPlanXml(p));
    EXPECT_DOUBLE_EQ(readPlanXml(dir.file("p.xml")).noiseUm, 0.25);
    test::writeText(dir.file("bad.xml"), "<plan machine=\"table-table-bc\" noise-um=\"-1\">\n"
                                         "<dbb5 name=\"XY\" kind=\"linear\" plane=\"XY\" LB=\"100\" ball=\"0 0 100\"/></plan>\n");
    try {
        readPlanXml(dir.file("bad.xml"));
        ADD_FAILURE() << "a negative noise-um was accepted";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("noise-um"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find(":1"), std::string::npos) << e.what();
    }
}

// The CLI of the issue: simulate with C's error motions, default identify. The warning comes first in the text, the
// JSON report carries the adequacy object, the HTML report a banner.
TEST(LsqAdequacy, CliWarnsFirstInTextJsonAndHtml) {
    test::ScratchDir dir("adequacy-cli");
    const std::string m = test::sourcePath("samples/machines/table-table-bc.xml");
    const std::string p = test::sourcePath("samples/plans/dbb5-table-table-bc.xml");
    const auto sim = test::runCli(fmt::format("simulate --machine {} --plan {} --deviations {} --noise-um 0.2 --seed 2 --out {}", m,
                                              p, test::sourcePath(kComponentsTruth), dir.file("t")));
    ASSERT_EQ(sim.exitCode, 0) << sim.out;
    const auto id = test::runCli(fmt::format("identify --machine {} --plan {} --traces {} --out {} --report {}", m, p,
                                             dir.file("t"), dir.file("d.csv"), dir.file("r.json")));
    ASSERT_EQ(id.exitCode, 0) << id.out;
    const size_t warn = id.out.find("WARNING: the model does not fit the data");
    ASSERT_NE(warn, std::string::npos) << id.out;
    EXPECT_LT(warn, id.out.find("identified 11 of 11")) << id.out;  // before the result's first line
    EXPECT_NE(id.out.find("component errors (error motions) of C"), std::string::npos) << id.out;
    EXPECT_NE(id.out.find("--params all"), std::string::npos) << id.out;
    const std::string json = test::readText(dir.file("r.json"));
    EXPECT_NE(json.find("\"adequacy\": {"), std::string::npos);
    EXPECT_NE(json.find("\"fits\": false"), std::string::npos);
    EXPECT_LT(json.find("\"adequacy\""), json.find("\"parameters\""));
    const auto html = test::runCli(fmt::format("identify --machine {} --plan {} --traces {} --out {} --report {}", m, p,
                                               dir.file("t"), dir.file("d2.csv"), dir.file("r.html")));
    ASSERT_EQ(html.exitCode, 0) << html.out;
    const std::string page = test::readText(dir.file("r.html"));
    EXPECT_NE(page.find("<div class=\"alarm\" role=\"alert\">WARNING: the model does not fit"), std::string::npos);
}

// The normal quickstart (recorded time-sampled CW/CCW files, 0.2 µm noise): the test must not fire.
TEST(LsqAdequacy, QuickstartDoesNotWarn) {
    test::ScratchDir dir("adequacy-quickstart");
    const std::string m = test::sourcePath("samples/machines/multitasking.xml");
    const std::string p = test::sourcePath("samples/plans/multitasking-six-circles-recorded.xml");
    const auto sim = test::runCli(fmt::format("simulate --machine {} --plan {} --deviations {} --noise-um 0.2 --seed 1 "
                                              "--instrument time --out {}",
                                              m, p, test::sourcePath("samples/deviations/multitasking-truth.csv"), dir.file("t")));
    ASSERT_EQ(sim.exitCode, 0) << sim.out;
    const auto id = test::runCli(fmt::format("identify --machine {} --plan {} --traces {} --out {} --report {}", m, p,
                                             dir.file("t"), dir.file("d.csv"), dir.file("r.json")));
    ASSERT_EQ(id.exitCode, 0) << id.out;
    EXPECT_EQ(id.out.find("WARNING"), std::string::npos) << id.out;
    EXPECT_NE(id.out.find("the model fits the data"), std::string::npos) << id.out;
    const std::string json = test::readText(dir.file("r.json"));
    EXPECT_NE(json.find("\"verdict\": \"the model fits the data\""), std::string::npos);
}

}  // namespace
}  // namespace cnccomp
