// The identification report as JSON: golden text for a hand-made report, read back with the JSON reader, a real
// report round trip, and malformed JSON named by line.
#include <gtest/gtest.h>

#include "cnccomp/error.hpp"
#include "cnccomp/identification/lsq.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "cnccomp/io/json.hpp"
#include "cnccomp/io/report_json.hpp"
#include "test_support.hpp"

namespace cnccomp {
using namespace cnccomp::identification;
using namespace cnccomp::io;
namespace {

IdentificationReport handMade() {
    IdentificationReport r;
    r.machine = "m";
    r.solver = "levenberg-marquardt";
    r.termination = "converged: step below tolerance";
    r.converged = true;
    r.iterations = 3;
    r.evaluations = 4;
    r.costBefore = 100;
    r.costAfter = 0.5;
    r.observations = 10;
    r.unknowns = 2;
    r.rank = 1;
    r.dof = 9;
    r.rankTolerance = 1e-7;
    r.sigma = 0.5 * kUm;
    r.conditionNumber = 1;
    r.singularValues = {2, 0};
    r.runs = {{"B-X", "ballbar", 10, 2 * kUm, 0.25 * kUm, 0.5 * kUm}};
    ParameterEstimate a;
    a.name = "EX0C1";
    a.alias = "dxBT";
    a.value = 12 * kUm;
    a.aliasValue = -12 * kUm;  // the value under the alias (here of the opposite sign, as for ISO EC0Y and gXY)
    a.stddev = 0.5 * kUm;
    a.lower95 = 11 * kUm;
    a.upper95 = 13 * kUm;
    ParameterEstimate b;
    b.name = "EB0B";
    b.angle = true;
    b.identified = false;
    b.value = 1 * kArcsec;
    r.parameters = {a, b};
    r.unidentified = {"EB0B"};
    r.identifiable = {{{"EX0C1", "EB0B"}, {1, -360}, "EX0C1 - 360·EB0B", false, 3 * kUm, 0.25 * kUm}};
    r.unobservable = {{{"EB0B"}, {1}, "EB0B", true, kNaN, kNaN}};
    r.covariance = Eigen::MatrixXd::Zero(2, 2);
    r.covariance(0, 0) = 2.5e-7;
    r.covariance(1, 1) = kNaN;
    r.warnings = {"1 of 2 unknowns are not \"identifiable\""};
    return r;
}

const char* kGolden = R"({
  "schema": "cnccomp-identification-report/1",
  "adequacy": {
    "tested": false,
    "fits": true,
    "verdict": "not tested",
    "test": "F = (sum r^2 / dof) / noise^2 per run and overall; noise from passes, the plan's noise-um, or successive differences",
    "confidence": 0.999,
    "statistic": null,
    "threshold": null,
    "dof": 0,
    "inflation": 1,
    "inflation_rule": "",
    "suspected_missing": [],
    "option": "",
    "message": "",
    "runs": []
  },
  "machine": "m",
  "method": "least-squares",
  "solver": "levenberg-marquardt",
  "termination": "converged: step below tolerance",
  "converged": true,
  "iterations": 3,
  "evaluations": 4,
  "cost_before_um2": 100,
  "cost_after_um2": 0.5,
  "observations": 10,
  "unknowns": 2,
  "rank": 1,
  "dof": 9,
  "rank_tolerance": 9.9999999999999995e-08,
  "sigma_um": 0.5,
  "condition_number": 1,
  "singular_values": [2, 0],
  "runs": [
    {
      "run": "B-X",
      "kind": "ballbar",
      "samples": 10,
      "rms_before_um": 2,
      "rms_after_um": 0.25,
      "max_after_um": 0.5
    }
  ],
  "parameters": [
    {
      "name": "EX0C1",
      "alias": "dxBT",
      "nuisance": false,
      "unit": "um",
      "identified": true,
      "start": 0,
      "value": 12,
      "alias_value": -12,
      "stddev": 0.5,
      "lower95": 11,
      "upper95": 13
    },
    {
      "name": "EB0B",
      "alias": "",
      "nuisance": false,
      "unit": "arcsec",
      "identified": false,
      "start": 0,
      "value": null,
      "stddev": null,
      "lower95": null,
      "upper95": null
    }
  ],
  "unidentified": ["EB0B"],
  "identifiable_combinations": [
    {
      "text": "EX0C1 - 360·EB0B",
      "names": ["EX0C1", "EB0B"],
      "coefficients": [1, -360],
      "unit": "um",
      "value": 3,
      "stddev": 0.25
    }
  ],
  "unobservable_directions": [
    {
      "text": "EB0B",
      "names": ["EB0B"],
      "coefficients": [1]
    }
  ],
  "monte_carlo_samples": 0,
  "covariance": [
    [2.4999999999999999e-07, 0],
    [0, null]
  ],
  "warnings": ["1 of 2 unknowns are not \"identifiable\""]
}
)";

TEST(LsqReportJson, GoldenText) {
    const std::string text = formatReportJson(handMade());
    EXPECT_EQ(text, kGolden);
}

TEST(LsqReportJson, ReadsBack) {
    const Json j = parseJson(formatReportJson(handMade()));
    EXPECT_EQ(j["schema"].string, "cnccomp-identification-report/1");
    EXPECT_TRUE(j["converged"].boolean);
    EXPECT_EQ(j["rank"].num(), 1);
    EXPECT_EQ(j["parameters"][0]["alias"].string, "dxBT");
    EXPECT_EQ(j["parameters"][0]["alias_value"].num(), -12.0);
    EXPECT_DOUBLE_EQ(j["parameters"][0]["upper95"].num(), 13);
    EXPECT_TRUE(std::isnan(j["parameters"][1]["value"].num()));
    EXPECT_EQ(j["identifiable_combinations"][0]["text"].string, "EX0C1 - 360·EB0B");
    EXPECT_DOUBLE_EQ(j["identifiable_combinations"][0]["coefficients"][1].num(), -360);
    EXPECT_EQ(j["warnings"][0].string, "1 of 2 unknowns are not \"identifiable\"");
    EXPECT_TRUE(std::isnan(j["covariance"][1][1].num()));
    EXPECT_FALSE(j.has("nothing"));
    EXPECT_THROW(j["nothing"], ModelError);
}

TEST(LsqReportJson, RealReportRoundTripsEveryNumber) {
    const MachineModel& m = test::multitasking();
    const DeviationSet truth = readDeviationCsv(test::sourcePath("samples/deviations/multitasking-truth.csv"), m);
    std::vector<BallbarRun> runs = readPlanXml(test::sourcePath("samples/plans/multitasking-six-circles.xml")).runs;
    const Kinematics k(m, truth);
    std::vector<BallbarTrace> traces;
    for (BallbarRun& r : runs) {
        r.stepDeg = 10;
        traces.push_back(simulateRun(k, r));
        for (size_t i = 0; i < traces.back().dL.size(); ++i) traces.back().dL[i] += 1e-4 * std::sin(7.0 * i);
    }
    const IdentificationResult r = identify(m, ballbarObservations(m, runs, traces));
    test::ScratchDir dir("report-json");
    writeReportJson(dir.file("r.json"), r.report);
    const Json j = readJsonFile(dir.file("r.json"));
    ASSERT_EQ(j["parameters"].array.size(), r.report.parameters.size());
    for (size_t i = 0; i < r.report.parameters.size(); ++i) {
        const ParameterEstimate& p = r.report.parameters[i];
        EXPECT_EQ(j["parameters"][i]["name"].string, p.name);
        EXPECT_DOUBLE_EQ(j["parameters"][i]["value"].num(), p.value / p.displayScale());  // 17 digits: exact
        EXPECT_DOUBLE_EQ(j["parameters"][i]["stddev"].num(), p.stddev / p.displayScale());
    }
    EXPECT_DOUBLE_EQ(j["sigma_um"].num(), r.report.sigma / kUm);
    EXPECT_EQ(j["covariance"].array.size(), 13u);
    EXPECT_DOUBLE_EQ(j["covariance"][2][3].num(), r.report.covariance(2, 3));
    EXPECT_EQ(j["runs"].array.size(), 6u);
}

TEST(LsqReportJson, MalformedJsonNamesTheLine) {
    try {
        parseJson("{\n  \"a\": 1,\n  \"b\": [1, 2,, 3]\n}", "x.json");
        FAIL();
    } catch (const InputError& e) {
        EXPECT_EQ(e.file(), "x.json");
        EXPECT_EQ(e.line(), 3);
    }
    EXPECT_THROW(parseJson("{\"a\": 1} trailing"), InputError);
    EXPECT_THROW(parseJson("\"unterminated"), InputError);
    EXPECT_THROW(parseJson("[1, nan]"), InputError);
    EXPECT_THROW(parseJson(std::string(1000, '[')), InputError);  // nesting limit, no stack overflow
    EXPECT_THROW(readJsonFile("/nonexistent/report.json"), InputError);
    EXPECT_EQ(parseJson("\"\\u00b5m\"").string, "µm");
}

}  // namespace
}  // namespace cnccomp
