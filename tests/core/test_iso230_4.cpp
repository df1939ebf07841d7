// ISO 230-4 circular test figures (cnccomp/circular_test.hpp) on traces built from shapes whose G, F, mean radius
// and H are known in closed form (the oracle is the construction, not our code), and the JSON summary of a report
// carrying them (golden numbers).
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <cmath>
#include <random>

#include "cnccomp/circular_test.hpp"
#include "cnccomp/error.hpp"
#include "cnccomp/io/json.hpp"
#include "cnccomp/io/report_json.hpp"
#include "app/report/html_report.hpp"

namespace cnccomp {
using namespace cnccomp::io;
namespace {

constexpr double LB = 100.0;

/// A path ρ(φ) = R + b·cos 2φ + h(φ) about the centre c, sampled at φ = k·step, seen by a ball bar whose centre ball
/// is at the origin: ΔL = |p| − LB at angle atan2(p). G = 2b (+ hysteresis part), mean radius R, by construction.
BallbarTrace shape(double R, double b, Eigen::Vector2d c, double stepDeg, int direction, double hysteresis = 0) {
    BallbarTrace t;
    const int n = static_cast<int>(std::lround(360.0 / stepDeg));
    for (int i = 0; i < n; ++i) {
        const int k = direction > 0 ? i : n - 1 - i;
        const double phi = k * stepDeg * kDeg;
        const double rho = R + b * std::cos(2 * phi) + hysteresis;
        const Eigen::Vector2d p = c + rho * Eigen::Vector2d(std::cos(phi), std::sin(phi));
        double a = std::atan2(p.y(), p.x()) / kDeg;
        if (a < -1e-9) a += 360.0;
        t.angleDeg.push_back(a);
        t.dL.push_back(p.norm() - LB);
    }
    return t;
}

// ---- An independent transcription of the ISO 230-4:2005 evaluation (clause 3 definitions), written from the standard,
// not from circular_test.cpp: the polar plot's points p_k = (LB + ΔL_k)(cos θ_k, sin θ_k); the least-squares circle
// (minimum Σ (|p_k − c| − r)², solved here by Gauss–Newton on (c_x, c_y, r) from the centroid); circular deviation
// G = max |p_k − c| − min |p_k − c|; radial deviation F = max / min ΔL (about the nominal centre); circular hysteresis
// H = the largest radial difference between the two directions, each pass's sample against the other pass linearly
// interpolated at its angle (within the angles both cover).
struct IsoFigures {
    double G = 0, Fmax = 0, Fmin = 0, radius = 0;
};

IsoFigures isoTranscription(const BallbarTrace& t, double lb) {
    const size_t n = t.dL.size();
    std::vector<double> x(n), y(n);
    double cx = 0, cy = 0;
    for (size_t k = 0; k < n; ++k) {
        const double a = t.angleDeg[k] * M_PI / 180.0, rho = lb + t.dL[k];
        x[k] = rho * std::cos(a);
        y[k] = rho * std::sin(a);
        cx += x[k] / n;
        cy += y[k] / n;
    }
    double r = 0;
    for (size_t k = 0; k < n; ++k) r += std::hypot(x[k] - cx, y[k] - cy) / n;
    for (int it = 0; it < 50; ++it) {  // Gauss–Newton: residual e_k = |p_k − c| − r
        double JtJ[3][3] = {}, Jte[3] = {};
        for (size_t k = 0; k < n; ++k) {
            const double dx = x[k] - cx, dy = y[k] - cy, d = std::hypot(dx, dy);
            const double J[3] = {-dx / d, -dy / d, -1.0}, e = d - r;
            for (int i = 0; i < 3; ++i) {
                Jte[i] += J[i] * e;
                for (int j = 0; j < 3; ++j) JtJ[i][j] += J[i] * J[j];
            }
        }
        // Solve JtJ·δ = −Jte by Cramer's rule.
        const auto det3 = [](double m[3][3]) {
            return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                   m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
        };
        const double D = det3(JtJ);
        double step[3];
        for (int c = 0; c < 3; ++c) {
            double m[3][3];
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j) m[i][j] = j == c ? -Jte[i] : JtJ[i][j];
            step[c] = det3(m) / D;
        }
        cx += step[0];
        cy += step[1];
        r += step[2];
        if (std::abs(step[0]) + std::abs(step[1]) + std::abs(step[2]) < 1e-15) break;
    }
    IsoFigures f;
    double lo = HUGE_VAL, hi = -HUGE_VAL;
    f.Fmin = HUGE_VAL;
    f.Fmax = -HUGE_VAL;
    for (size_t k = 0; k < n; ++k) {
        const double d = std::hypot(x[k] - cx, y[k] - cy);
        lo = std::min(lo, d);
        hi = std::max(hi, d);
        f.Fmax = std::max(f.Fmax, t.dL[k]);
        f.Fmin = std::min(f.Fmin, t.dL[k]);
    }
    f.G = hi - lo;
    f.radius = r;
    return f;
}

double hysteresisTranscription(const BallbarTrace& a, const BallbarTrace& b) {
    const auto at = [](const BallbarTrace& t, double angle, double& v) {  // linear interpolation, t in any order
        for (size_t i = 0; i + 1 < t.dL.size(); ++i) {
            const double a0 = t.angleDeg[i], a1 = t.angleDeg[i + 1];
            if (a0 == a1 || angle < std::min(a0, a1) || angle > std::max(a0, a1)) continue;
            v = t.dL[i] + (angle - a0) / (a1 - a0) * (t.dL[i + 1] - t.dL[i]);
            return true;
        }
        return false;
    };
    double h = 0;
    for (const auto& [p, q] : {std::pair{&a, &b}, std::pair{&b, &a}})
        for (size_t k = 0; k < p->dL.size(); ++k) {
            double v = 0;
            if (at(*q, p->angleDeg[k], v)) h = std::max(h, std::abs(p->dL[k] - v));
        }
    return h;
}

// Oracle: the transcription above, on traces with an off-centre pivot, harmonics of orders 2–5, random noise and a
// CCW/CW difference, over whole turns and the 220° arcs of the vertical planes.
TEST(Iso230_4, AgreesWithAnIndependentTranscriptionOfTheStandard) {
    std::mt19937_64 rng(11);
    std::normal_distribution<double> noise(0.0, 0.3e-3);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (int trial = 0; trial < 20; ++trial) {
        const double arc = trial % 2 ? 220.0 : 360.0, start = trial % 2 ? -20.0 : 0.0, step = 1.0;
        const double ex = 5e-3 * u(rng), ey = 5e-3 * u(rng);
        double c[6];
        for (double& v : c) v = 4e-3 * u(rng);
        BallbarTrace ccw, cw;
        const int n = static_cast<int>(arc / step) + (arc < 360 ? 1 : 0);
        for (int k = 0; k < n; ++k) {
            const double a = start + k * step, t = a * kDeg;
            const double shape = ex * std::cos(t) + ey * std::sin(t) + c[0] * std::cos(2 * t) + c[1] * std::sin(3 * t) +
                                 c[2] * std::cos(5 * t);
            ccw.angleDeg.push_back(a);
            ccw.dL.push_back(shape + noise(rng));
            cw.angleDeg.insert(cw.angleDeg.begin(), a);
            cw.dL.insert(cw.dL.begin(), shape + c[3] + c[4] * std::sin(t) + noise(rng));
        }
        for (const BallbarTrace* t : {&ccw, &cw}) {
            const CircularTestResult ours = evaluateCircularTest(*t, LB);
            const IsoFigures iso = isoTranscription(*t, LB);
            EXPECT_NEAR(ours.circularity, iso.G, 1e-9) << trial;
            EXPECT_NEAR(ours.radialMax, iso.Fmax, 1e-12) << trial;
            EXPECT_NEAR(ours.radialMin, iso.Fmin, 1e-12) << trial;
            EXPECT_NEAR(ours.meanRadius, iso.radius, 1e-9) << trial;
        }
        EXPECT_NEAR(circularHysteresis(ccw, cw), hysteresisTranscription(ccw, cw), 1e-12) << trial;
    }
}

TEST(Iso230_4, CircularDeviationRadialDeviationAndMeanRadiusOfAKnownShape) {
    const double R = LB + 3 * kUm, b = 4 * kUm;
    const Eigen::Vector2d c(5 * kUm, -2 * kUm);
    const BallbarTrace t = shape(R, b, c, 1.0, +1);
    const CircularTestResult r = evaluateCircularTest(t, LB);
    // The shape is point-symmetric about c, so the least-squares centre is c and the radius the mean of ρ.
    EXPECT_NEAR(r.center.x(), c.x(), 1e-9);
    EXPECT_NEAR(r.center.y(), c.y(), 1e-9);
    EXPECT_NEAR(r.meanRadius, R, 1e-9);
    EXPECT_NEAR(r.meanRadialError, 3 * kUm, 1e-9);
    EXPECT_NEAR(r.circularity, 2 * b, 1e-9);  // G = max ρ − min ρ
    // F about the nominal centre: |p| − LB, largest and smallest over the samples (to first order R−LB ± (b + |c|)).
    double hi = -1, lo = 1;
    for (int k = 0; k < 360; ++k) {
        const double phi = k * kDeg;
        const double v = (c + (R + b * std::cos(2 * phi)) * Eigen::Vector2d(std::cos(phi), std::sin(phi))).norm() - LB;
        hi = std::max(hi, v);
        lo = std::min(lo, v);
    }
    EXPECT_NEAR(r.radialMax, hi, 1e-12);
    EXPECT_NEAR(r.radialMin, lo, 1e-12);
    EXPECT_GT(r.radialMax, 3 * kUm + 4 * kUm);  // the eccentricity adds to F, not to G
}

TEST(Iso230_4, HysteresisIsTheLargestRadialGapBetweenCcwAndCw) {
    const double R = LB, b = 2 * kUm;
    const Eigen::Vector2d c(1 * kUm, 1 * kUm);
    // The CW path lies 1.5 µm outside the CCW path everywhere.
    const BallbarTrace ccw = shape(R, b, c, 1.0, +1), cw = shape(R, b, c, 1.0, -1, 1.5 * kUm);
    const CircularRunResult run = evaluateCircularRun({{+1, ccw}, {-1, cw}}, LB);
    ASSERT_EQ(run.passes.size(), 2u);
    EXPECT_NEAR(run.hysteresis, 1.5 * kUm, 2e-4 * kUm);  // the centre shift makes it first order exact
    EXPECT_GT(run.hysteresisSamples, 700);
    EXPECT_NEAR(run.circularDeviation, 2 * b, 1e-9);
    EXPECT_NEAR(run.meanRadius, R + 0.75 * kUm, 1e-9);
    // One direction only: no hysteresis.
    EXPECT_TRUE(std::isnan(evaluateCircularRun({{+1, ccw}}, LB).hysteresis));
    // A gap that varies: ρ_cw − ρ_ccw = 2 µm · |sin φ| peaks at 90° and 270°.
    BallbarTrace cw2 = ccw;
    for (size_t i = 0; i < cw2.dL.size(); ++i) cw2.dL[i] += 2 * kUm * std::abs(std::sin(cw2.angleDeg[i] * kDeg));
    EXPECT_NEAR(circularHysteresis(ccw, cw2), 2 * kUm, 1e-4 * kUm);
    EXPECT_THROW(evaluateCircularRun({}, LB), ModelError);
    EXPECT_THROW(evaluateCircularRun({{0, ccw}}, LB), ModelError);
}

TEST(Iso230_4, PartialArcsOverlapOnlyWhereBothPassesRun) {
    BallbarTrace a, b;
    for (int k = 0; k <= 90; ++k) a.angleDeg.push_back(k), a.dL.push_back(0.0);
    for (int k = 60; k <= 180; ++k) b.angleDeg.push_back(k), b.dL.push_back(k <= 90 ? 1e-3 : 1.0);
    int n = 0;
    EXPECT_NEAR(circularHysteresis(a, b, &n), 1e-3, 1e-12);  // only 60..90° compared
    EXPECT_EQ(n, 31 + 31);
    BallbarTrace far;
    far.angleDeg = {200, 210};
    far.dL = {0, 0};
    EXPECT_TRUE(std::isnan(circularHysteresis(a, far, &n)));
    EXPECT_EQ(n, 0);
}

TEST(Iso230_4, JsonSummaryCarriesTheFiguresGolden) {
    const double R = LB + 3 * kUm, b = 4 * kUm;
    const Eigen::Vector2d c(5 * kUm, -2 * kUm);
    const BallbarTrace ccw = shape(R, b, c, 1.0, +1), cw = shape(R, b, c, 1.0, -1, 1.5 * kUm);
    app::report::ReportData d;
    d.title = "golden";
    d.machine = "m";
    app::report::RunSection r;
    r.name = "C-X";
    r.test = "C-X";
    r.LB = LB;
    r.passes.push_back({+1, ccw.angleDeg, ccw.dL, {}});
    r.passes.push_back({-1, cw.angleDeg, cw.dL, {}});
    r.before = app::report::isoFigures(evaluateCircularRun({{+1, ccw}, {-1, cw}}, LB));
    d.runs.push_back(r);
    d.deviations.push_back({"EB0B", "bXB", "arcsec", true, 9.1234, 8.5, 9.75, 9.0});
    d.deviations.push_back({"EC0Y", "gXY", "arcsec", false});
    const app::report::ReportFiles files = app::report::reportFiles("out/r.html", d);
    const Json j = parseJson(app::report::formatReportSummaryJson(d, files), "summary");
    EXPECT_EQ(j["schema"].string, "cnccomp-report-summary/1");
    const Json& run = j["runs"][0];
    EXPECT_EQ(run["name"].string, "C-X");
    EXPECT_EQ(run["samples"].num(), 720);
    EXPECT_EQ(run["passes"][1].string, "cw");
    EXPECT_NEAR(run["before"]["G_um"].num(), 8.0, 1e-6);          // 2b
    EXPECT_NEAR(run["before"]["H_um"].num(), 1.5, 2e-4);          // the CW offset
    EXPECT_NEAR(run["before"]["mean_radius_mm"].num(), 100.00375, 1e-8);  // R + 0.75 µm
    EXPECT_EQ(run["after"]["G_um"].type, Json::Type::Null);  // no after traces
    EXPECT_EQ(run["plot"].string, "r-polar-C-X.svg");
    EXPECT_NEAR(j["deviations"][0]["value"].num(), 9.1234, 1e-12);
    EXPECT_NEAR(j["deviations"][0]["low95"].num(), 8.5, 1e-12);
    EXPECT_NEAR(j["deviations"][0]["truth"].num(), 9.0, 1e-12);
    EXPECT_FALSE(j["deviations"][1]["identified"].boolean);
    EXPECT_EQ(j["deviations"][1]["value"].type, Json::Type::Null);
    ASSERT_EQ(j["unidentified"].array.size(), 1u);
    EXPECT_EQ(j["unidentified"][0].string, "EC0Y");
}

}  // namespace
}  // namespace cnccomp
