// Uncertainty of the least-squares engine with ball-bar noise σ = 0.5 µm over 200 seeded trials on the six
// [MultiTasking] runs (10° steps to keep the test lean): the reported 95 % intervals cover the truth, and the
// least-squares estimate beats the closed-form formulas (17)–(28) on the same noisy traces.
#include <gtest/gtest.h>

#include <random>

#include "cnccomp/closed_form.hpp"
#include "cnccomp/eccentricity.hpp"
#include "cnccomp/identification/lsq.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "test_support.hpp"

namespace cnccomp {
using namespace cnccomp::identification;
using namespace cnccomp::io;
namespace {

struct Trials {
    int covered = 0, total = 0;
    double lsqSquared = 0, closedSquared = 0;  ///< Σ error² over the 12 closed-form deviations
    int lsqBetter = 0, trials = 0;
};

TEST(LsqNoise, IntervalsCoverTruthAndLeastSquaresBeatsClosedForm) {
    const MachineModel& m = test::multitasking();
    const DeviationSet truth = readDeviationCsv(test::sourcePath("samples/deviations/multitasking-truth.csv"), m);
    std::vector<BallbarRun> runs = readPlanXml(test::sourcePath("samples/plans/multitasking-six-circles.xml")).runs;
    for (BallbarRun& r : runs) r.stepDeg = 10.0;
    const Kinematics k(m, truth);
    std::vector<BallbarTrace> clean;
    for (const BallbarRun& r : runs) clean.push_back(simulateRun(k, r));
    const std::vector<std::string> twelve{"dxBT", "dzBT", "aBT", "aXB", "bXB", "gXB", "aYZ", "bYZ", "dxCZ", "dyCZ", "aCZ", "bCZ"};

    const double sigma = 0.5 * kUm;
    std::mt19937_64 rng(20240601);
    std::normal_distribution<double> noise(0.0, sigma);
    Trials t;
    for (int trial = 0; trial < 200; ++trial) {
        std::vector<BallbarTrace> traces = clean;
        for (BallbarTrace& tr : traces)
            for (double& v : tr.dL) v += noise(rng);
        const IdentificationResult r = identify(m, ballbarObservations(m, runs, traces));
        ASSERT_TRUE(r.report.converged) << r.report.termination;
        ASSERT_EQ(r.report.rank, 13);
        EXPECT_NEAR(r.report.sigma, sigma, 0.25 * sigma);  // σ̂ from the residuals
        for (const ParameterEstimate& p : r.report.parameters) {
            const double tv = truth.get(p.name);
            t.covered += (p.lower95 <= tv && tv <= p.upper95) ? 1 : 0;
            ++t.total;
        }
        const auto rows = eccentricitiesFromTraces(m, runs, traces);
        const DeviationSet formulas = identifyClosedForm(m, rows, ClosedFormOptions{0, 10.0});
        double lsq = 0, cf = 0;
        for (const std::string& n : twelve) {
            const double unit = m.deviations[m.deviationIndex(n)].isAngle() ? kArcsec : kUm;
            const auto sq = [&](double v) { return (v - truth.get(n)) / unit * (v - truth.get(n)) / unit; };
            lsq += sq(r.deviations.get(n));
            cf += sq(formulas.get(n));
        }
        t.lsqSquared += lsq;
        t.closedSquared += cf;
        t.lsqBetter += lsq < cf ? 1 : 0;
        ++t.trials;
    }
    const double coverage = static_cast<double>(t.covered) / t.total;
    const double rmsLsq = std::sqrt(t.lsqSquared / (12.0 * t.trials));
    const double rmsClosed = std::sqrt(t.closedSquared / (12.0 * t.trials));
    RecordProperty("coverage", std::to_string(coverage));
    RecordProperty("rms_error_lsq", std::to_string(rmsLsq));
    RecordProperty("rms_error_closed_form", std::to_string(rmsClosed));
    std::printf("coverage %.4f  RMS error (um|arcsec): least squares %.4f, closed form %.4f; "
                "least squares better in %d/%d trials\n", coverage, rmsLsq, rmsClosed, t.lsqBetter, t.trials);
    EXPECT_GE(coverage, 0.90);
    EXPECT_LE(coverage, 0.99);  // intervals are not uselessly wide either
    EXPECT_LT(rmsLsq, rmsClosed);
}

TEST(LsqNoise, MonteCarloAgreesWithLinearisedCovariance) {
    const MachineModel& m = test::multitasking();
    const DeviationSet truth = readDeviationCsv(test::sourcePath("samples/deviations/multitasking-truth.csv"), m);
    std::vector<BallbarRun> runs = readPlanXml(test::sourcePath("samples/plans/multitasking-six-circles.xml")).runs;
    for (BallbarRun& r : runs) r.stepDeg = 10.0;
    const Kinematics k(m, truth);
    std::mt19937_64 rng(7);
    std::normal_distribution<double> noise(0.0, 0.5 * kUm);
    std::vector<BallbarTrace> traces;
    for (const BallbarRun& r : runs) {
        traces.push_back(simulateRun(k, r));
        for (double& v : traces.back().dL) v += noise(rng);
    }
    IdentifyOptions o;
    o.monteCarlo = 120;
    o.seed = 11;
    const IdentificationResult r = identify(m, ballbarObservations(m, runs, traces), o);
    EXPECT_EQ(r.report.monteCarloSamples, 120);
    for (const ParameterEstimate& p : r.report.parameters) {
        // 120 samples: the sampled standard deviation is within ±25 % of the linearised one (≈ 4σ of its spread).
        EXPECT_NEAR(p.mcStddev / p.stddev, 1.0, 0.25) << p.name;
        EXPECT_LT(p.mcLower95, p.value);
        EXPECT_GT(p.mcUpper95, p.value);
        EXPECT_NEAR((p.mcUpper95 - p.mcLower95) / (p.upper95 - p.lower95), 1.0, 0.35) << p.name;
    }
    // Same seed, same answer.
    const IdentificationResult again = identify(m, ballbarObservations(m, runs, traces), o);
    EXPECT_EQ(again.report.parameters[3].mcStddev, r.report.parameters[3].mcStddev);
}

}  // namespace
}  // namespace cnccomp
