// ISO 230-2 evaluation of bidirectional laser runs (cnccomp/laser_positioning.hpp).
// Oracles: (1) an independent transcription of the standard's formulas (ISO 230-2:2014 clause 2), written here from
// the standard's text with its own loops and data layout (deviation[direction][target][run]), agreeing on random
// data; (2) a hand-made case whose figures follow by inspection; (3) bad input gets InputError naming the file.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "cnccomp/error.hpp"
#include "cnccomp/laser_positioning.hpp"

namespace cnccomp {
namespace {

/// The standard's evaluation, transcribed apart from ours. x[d][i][j]: direction d (0 = ↑, 1 = ↓), target i, run j.
struct Iso230_2Figures {
    double E, Eup, Edown, M, A, Aup, Adown, B, Bmean, R, Rup, Rdown;
    std::vector<double> xbarUp, xbarDown, Bi, Ri;
};
Iso230_2Figures transcription(const std::vector<std::vector<std::vector<double>>>& x) {
    const int m = static_cast<int>(x[0].size()), n = static_cast<int>(x[0][0].size());
    Iso230_2Figures f{};
    std::vector<double> s[2];
    for (int d = 0; d < 2; ++d) {
        for (int i = 0; i < m; ++i) {
            double mean = 0;
            for (int j = 0; j < n; ++j) mean += x[d][i][j] / n;  // x̄_i = (1/n) Σ x_ij
            double var = 0;
            for (int j = 0; j < n; ++j) var += (x[d][i][j] - mean) * (x[d][i][j] - mean);
            s[d].push_back(std::sqrt(var / (n - 1)));  // s_i = √(1/(n−1) Σ (x_ij − x̄_i)²)
            (d == 0 ? f.xbarUp : f.xbarDown).push_back(mean);
        }
    }
    // Clause 2: B_i = x̄_i↑ − x̄_i↓, B = max|B_i|, B̄ = (1/m) Σ B_i; R_i↑ = 4 s_i↑; R_i = max[2s↑ + 2s↓ + |B_i|; R↑; R↓].
    f.B = 0;
    f.Bmean = 0;
    f.R = f.Rup = f.Rdown = 0;
    for (int i = 0; i < m; ++i) {
        const double b = f.xbarUp[i] - f.xbarDown[i];
        f.Bi.push_back(b);
        f.B = std::max(f.B, std::fabs(b));
        f.Bmean += b / m;
        const double ru = 4 * s[0][i], rd = 4 * s[1][i];
        double ri = 2 * s[0][i] + 2 * s[1][i] + std::fabs(b);
        if (ru > ri) ri = ru;
        if (rd > ri) ri = rd;
        f.Ri.push_back(ri);
        f.Rup = std::max(f.Rup, ru);
        f.Rdown = std::max(f.Rdown, rd);
        f.R = std::max(f.R, ri);
    }
    // E↑ = max x̄↑ − min x̄↑; E = max(x̄↑, x̄↓) − min(x̄↑, x̄↓); M = max x̄ − min x̄ with x̄ = (x̄↑ + x̄↓)/2;
    // A↑ = max(x̄↑ + 2s↑) − min(x̄↑ − 2s↑); A = max(x̄↑ + 2s↑; x̄↓ + 2s↓) − min(x̄↑ − 2s↑; x̄↓ − 2s↓).
    double upMax = -1e300, upMin = 1e300, dnMax = -1e300, dnMin = 1e300, mMax = -1e300, mMin = 1e300;
    double auMax = -1e300, auMin = 1e300, adMax = -1e300, adMin = 1e300;
    for (int i = 0; i < m; ++i) {
        upMax = std::max(upMax, f.xbarUp[i]);
        upMin = std::min(upMin, f.xbarUp[i]);
        dnMax = std::max(dnMax, f.xbarDown[i]);
        dnMin = std::min(dnMin, f.xbarDown[i]);
        const double mean = 0.5 * (f.xbarUp[i] + f.xbarDown[i]);
        mMax = std::max(mMax, mean);
        mMin = std::min(mMin, mean);
        auMax = std::max(auMax, f.xbarUp[i] + 2 * s[0][i]);
        auMin = std::min(auMin, f.xbarUp[i] - 2 * s[0][i]);
        adMax = std::max(adMax, f.xbarDown[i] + 2 * s[1][i]);
        adMin = std::min(adMin, f.xbarDown[i] - 2 * s[1][i]);
    }
    f.Eup = upMax - upMin;
    f.Edown = dnMax - dnMin;
    f.E = std::max(upMax, dnMax) - std::min(upMin, dnMin);
    f.M = mMax - mMin;
    f.Aup = auMax - auMin;
    f.Adown = adMax - adMin;
    f.A = std::max(auMax, adMax) - std::min(auMin, adMin);
    return f;
}

TEST(LaserPositioning, AgreesWithAnIndependentTranscriptionOfIso230_2OnRandomRuns) {
    std::mt19937_64 rng(230);
    for (int trial = 0; trial < 50; ++trial) {
        std::uniform_int_distribution<int> targets(5, 21), runs(5, 10);
        const int m = targets(rng), n = runs(rng);
        std::normal_distribution<double> noise(0, 1.5), pitch(0, 6);
        LaserPositioningRuns in;
        in.axis = "Y";
        for (int i = 0; i < m; ++i) in.targets.push_back(-200 + 37.5 * i);
        std::vector<double> sys(m);
        for (double& v : sys) v = pitch(rng);
        const double backlash = std::uniform_real_distribution<double>(-4, 8)(rng);
        std::vector<std::vector<std::vector<double>>> x(2, std::vector<std::vector<double>>(m, std::vector<double>(n)));
        in.forward.assign(n, std::vector<double>(m));
        in.reverse.assign(n, std::vector<double>(m));
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < m; ++i) {
                in.forward[j][i] = x[0][i][j] = sys[i] + backlash / 2 + noise(rng);
                in.reverse[j][i] = x[1][i][j] = sys[i] - backlash / 2 + noise(rng);
            }
        const LaserPositioningResult r = evaluateLaserPositioning(in);
        const Iso230_2Figures f = transcription(x);
        const double tol = 1e-9;
        EXPECT_NEAR(r.E, f.E, tol);
        EXPECT_NEAR(r.EForward, f.Eup, tol);
        EXPECT_NEAR(r.EReverse, f.Edown, tol);
        EXPECT_NEAR(r.M, f.M, tol);
        EXPECT_NEAR(r.A, f.A, tol);
        EXPECT_NEAR(r.AForward, f.Aup, tol);
        EXPECT_NEAR(r.AReverse, f.Adown, tol);
        EXPECT_NEAR(r.B, f.B, tol);
        EXPECT_NEAR(r.meanReversal, f.Bmean, tol);
        EXPECT_NEAR(r.R, f.R, tol);
        EXPECT_NEAR(r.RForward, f.Rup, tol);
        EXPECT_NEAR(r.RReverse, f.Rdown, tol);
        ASSERT_EQ(r.targets.size(), static_cast<size_t>(m));
        for (int i = 0; i < m; ++i) {
            EXPECT_NEAR(r.targets[i].meanForward, f.xbarUp[i], tol);
            EXPECT_NEAR(r.targets[i].meanReverse, f.xbarDown[i], tol);
            EXPECT_NEAR(r.targets[i].reversal, f.Bi[i], tol);
            EXPECT_NEAR(r.targets[i].repeatability, f.Ri[i], tol);
        }
    }
}

TEST(LaserPositioning, HandMadeRunsGiveTheFiguresByInspection) {
    // Five targets, five runs; forward deviation = 2·i µm, reverse = 2·i − 3 µm, no scatter: s = 0, so
    // E↑ = E↓ = 8, E = 8 − (−3) = 11, B_i = 3 = B = B̄, R = max(|B_i|) = 3 (2s + 2s + |B|), M = 8, A = E = 11.
    LaserPositioningRuns in;
    in.source = "x-axis.csv";
    in.targets = {0, 100, 200, 300, 400};
    for (int j = 0; j < 5; ++j) {
        in.forward.push_back({0, 2, 4, 6, 8});
        in.reverse.push_back({-3, -1, 1, 3, 5});
    }
    in.environmentCompensated = true;
    const LaserPositioningResult r = evaluateLaserPositioning(in);
    EXPECT_DOUBLE_EQ(r.EForward, 8);
    EXPECT_DOUBLE_EQ(r.EReverse, 8);
    EXPECT_DOUBLE_EQ(r.E, 11);
    EXPECT_DOUBLE_EQ(r.B, 3);
    EXPECT_DOUBLE_EQ(r.meanReversal, 3);
    EXPECT_DOUBLE_EQ(r.R, 3);
    EXPECT_DOUBLE_EQ(r.RForward, 0);
    EXPECT_DOUBLE_EQ(r.M, 8);
    EXPECT_DOUBLE_EQ(r.A, 11);
    EXPECT_TRUE(r.warnings.empty());
    // The positioning error as a function of position: linear between targets, constant outside.
    EXPECT_DOUBLE_EQ(r.errorAt(150, true), 3);
    EXPECT_DOUBLE_EQ(r.errorAt(150, false), 0);
    EXPECT_DOUBLE_EQ(r.errorAt(-50, true), 0);
    EXPECT_DOUBLE_EQ(r.errorAt(1000, false), 5);
    EXPECT_DOUBLE_EQ(r.errorAt(400, true), 8);
    // One run 1 µm off at target 3 forward: s_3↑ = √(Σ(x − x̄)²/4) with x̄ = 4.2 → R_3↑ = 4·s.
    in.forward[2][2] = 5;
    in.environmentCompensated = false;
    const LaserPositioningResult q = evaluateLaserPositioning(in);
    const double s = std::sqrt((4 * 0.2 * 0.2 + 0.8 * 0.8) / 4);
    EXPECT_NEAR(q.targets[2].repeatabilityForward, 4 * s, 1e-12);
    EXPECT_NEAR(q.targets[2].meanForward, 4.2, 1e-12);
    EXPECT_FALSE(q.warnings.empty());  // environment compensation stated as not done
}

TEST(LaserPositioning, BadInputGetsInputErrors) {
    LaserPositioningRuns good;
    good.source = "laser.csv";
    good.targets = {0, 50, 100, 150, 200};
    good.forward.assign(5, std::vector<double>(5, 1.0));
    good.reverse.assign(5, std::vector<double>(5, -1.0));
    EXPECT_NO_THROW(evaluateLaserPositioning(good));
    const auto expectError = [](const LaserPositioningRuns& in, const std::string& part) {
        try {
            (void)evaluateLaserPositioning(in);
            ADD_FAILURE() << "no error; expected '" << part << "'";
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
            EXPECT_EQ(e.file(), "laser.csv");
        }
    };
    LaserPositioningRuns oneDir = good;
    oneDir.reverse.clear();
    expectError(oneDir, "one direction only");
    LaserPositioningRuns unequal = good;
    unequal.reverse.pop_back();
    unequal.minimumRuns = 3;
    expectError(unequal, "5 forward runs but 4 reverse runs");
    LaserPositioningRuns few = good;
    few.forward.pop_back();
    few.reverse.pop_back();
    expectError(few, "at least 5");
    LaserPositioningRuns order = good;
    order.targets[3] = 90;
    expectError(order, "strictly increasing");
    LaserPositioningRuns nan = good;
    nan.reverse[2][4] = std::nan("");
    expectError(nan, "reverse run 3 at target 5");
    LaserPositioningRuns shortRun = good;
    shortRun.forward[1].pop_back();
    expectError(shortRun, "one per target");
    LaserPositioningRuns fewTargets = good;
    fewTargets.targets.pop_back();
    for (auto& r : fewTargets.forward) r.pop_back();
    for (auto& r : fewTargets.reverse) r.pop_back();
    expectError(fewTargets, "at least five");
}

}  // namespace
}  // namespace cnccomp
