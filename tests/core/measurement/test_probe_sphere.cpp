// Touch probe and calibration sphere: the known-radius sphere fit, the plan's commands, the probe result
// file, the centre observations and their identification.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <map>
#include <random>
#include <sstream>

#include "cnccomp/error.hpp"
#include "cnccomp/identification/lsq.hpp"
#include "cnccomp/identification/sphere_probe.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "cnccomp/io/probe_log.hpp"
#include "cnccomp/measurement/sphere_fit.hpp"
#include "test_support.hpp"

namespace cnccomp {
using namespace cnccomp::identification;
using namespace cnccomp::io;
using namespace cnccomp::measurement;
namespace {

const MachineModel& tableTable() { return test::sampleMachine("table-table-ac"); }
MeasurementPlan samplePlan() { return readPlanXml(test::sourcePath("samples/plans/table-table-ac-sphere.xml")); }

/// Independent oracle: the algebraic (linear) sphere fit with a free radius — |p|² = 2 p·c + (r² − |c|²) is linear in
/// (c, r² − |c|²) — solved by QR. Written apart from fitSphereKnownRadius (Gauss–Newton on |p − c| − r).
Vec3 algebraicCentre(const std::vector<Vec3>& pts, double* radius = nullptr) {
    Eigen::MatrixXd A(static_cast<Eigen::Index>(pts.size()), 4);
    Eigen::VectorXd b(static_cast<Eigen::Index>(pts.size()));
    for (size_t i = 0; i < pts.size(); ++i) {
        const auto r = static_cast<Eigen::Index>(i);
        A.row(r) << 2 * pts[i].x(), 2 * pts[i].y(), 2 * pts[i].z(), 1.0;
        b[r] = pts[i].squaredNorm();
    }
    const Eigen::Vector4d s = A.colPivHouseholderQr().solve(b);
    if (radius) *radius = std::sqrt(s[3] + s.head<3>().squaredNorm());
    return s.head<3>();
}

/// Pole and n points at latitude phi (rad) of a sphere of radius r about c, tool axis +Z.
std::vector<Vec3> pattern(const Vec3& c, double r, double phi, int n) {
    std::vector<Vec3> p{c + r * Vec3::UnitZ()};
    for (int k = 0; k < n; ++k) {
        const double th = 2 * M_PI * k / n;
        p.push_back(c + r * Vec3(std::cos(phi) * std::cos(th), std::cos(phi) * std::sin(th), std::sin(phi)));
    }
    return p;
}

TEST(SphereFit, ExactPointsGiveTheCentreAsTheAlgebraicFitDoes) {
    // Oracle: the algebraic linear fit above, on points exactly on a sphere (any pattern that fixes the centre).
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(-1, 1);
    for (int trial = 0; trial < 20; ++trial) {
        const Vec3 c(100 * u(rng), 100 * u(rng), 100 * u(rng));
        const double r = 15.5 + 5 * u(rng);
        std::vector<Vec3> pts;
        for (int k = 0; k < 7; ++k) pts.push_back(c + r * Vec3(u(rng), u(rng), 0.2 + std::abs(u(rng))).normalized());
        double ra = 0;
        const Vec3 ca = algebraicCentre(pts, &ra);
        const SphereFit f = fitSphereKnownRadius(pts, r, c + Vec3(0.3, -0.2, 0.4));
        EXPECT_LT((f.centre - ca).norm(), 1e-9) << trial;
        EXPECT_NEAR(ra, r, 1e-9);
        EXPECT_LT(f.rms, 1e-10);
    }
}

TEST(SphereFit, ARadiusMismatchMovesTheCentreAlongThePoleAsTheOneDimensionalMinimumSays) {
    // Oracle: the symmetric pattern (pole + 4 at latitude) on a sphere of radius r + δ, fitted with radius r, has its
    // centre on the axis (symmetry); its height minimises the sum of squares S(z), found here by golden-section search
    // on S itself (no derivatives, no Gauss–Newton).
    const double r = 15.5, delta = 0.02, phi = 20 * kDeg;
    const std::vector<Vec3> pts = pattern(Vec3::Zero(), r + delta, phi, 4);
    const auto S = [&](double z) {
        double s = 0;
        for (const Vec3& p : pts) s += std::pow((p - Vec3(0, 0, z)).norm() - r, 2);
        return s;
    };
    double a = -1, b = 1;
    const double g = (std::sqrt(5.0) - 1) / 2;
    for (int i = 0; i < 200; ++i) {
        const double x1 = b - g * (b - a), x2 = a + g * (b - a);
        (S(x1) < S(x2) ? b : a) = S(x1) < S(x2) ? x2 : x1;
    }
    const SphereFit f = fitSphereKnownRadius(pts, r, Vec3::Zero());
    EXPECT_NEAR(f.centre.z(), 0.5 * (a + b), 1e-7);  // golden section finds a quadratic minimum to about √ε
    EXPECT_NEAR(f.centre.x(), 0, 1e-12);
    EXPECT_NEAR(f.centre.y(), 0, 1e-12);
    EXPECT_GT(f.centre.z(), 0.5 * delta);  // the pole pulls the centre up by about δ
}

TEST(SphereFit, RefusesTooFewTouchesOrALine) {
    EXPECT_THROW(fitSphereKnownRadius({Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)}, 1, Vec3::Zero()), ModelError);
    EXPECT_THROW(fitSphereKnownRadius({Vec3(1, 0, 0), Vec3(2, 0, 0), Vec3(3, 0, 0), Vec3(4, 0, 0)}, 1, Vec3(0, 0, 0)),
                 ModelError);
}

// ---- the plan --------------------------------------------------------------------------------------------------------

TEST(SpherePlan, SampleReadsWritesAndReadsBackTheSamePoses) {
    const MeasurementPlan p = samplePlan();
    ASSERT_EQ(p.sphereRuns.size(), 1u);
    const SphereRun& r = p.sphereRuns[0];
    EXPECT_EQ(r.poses().size(), 23u);  // C at A = 0 (8), C at A = 45 (8), A -90..90 (7)
    EXPECT_DOUBLE_EQ(r.fitRadius(), 15.5);
    test::ScratchDir dir("sphere-plan");
    writePlanXml(dir.file("p.xml"), p);
    const MeasurementPlan q = readPlanXml(dir.file("p.xml"));
    ASSERT_EQ(q.sphereRuns.size(), 1u);
    EXPECT_EQ(q.sphereRuns[0].poses(), r.poses());
    EXPECT_EQ(q.sphereRuns[0].estimateTrigger, r.estimateTrigger);
    EXPECT_EQ(q.sphereRuns[0].centre, r.centre);
}

TEST(SpherePlan, BadElementsNameFileAndLine) {
    test::ScratchDir dir("sphere-plan-bad");
    const auto expectError = [&](const std::string& body, const std::string& what) {
        test::writeText(dir.file("p.xml"), "<plan>\n" + body + "\n</plan>\n");
        try {
            readPlanXml(dir.file("p.xml"));
            FAIL() << "expected an error for " << body;
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
            EXPECT_EQ(e.line(), 2) << e.what();
        }
    };
    expectError(R"(<sphere name="s" centre="0 0 0" diameter="25" stylus-diameter="6" ring="3"><pose A="0"/></sphere>)", "ring");
    expectError(R"(<sphere name="s" centre="0 0 0" diameter="25" stylus-diameter="6"/>)", "no pose");
    expectError(R"(<sphere name="s" centre="0 0 0" diameter="25"><pose A="0"/></sphere>)", "stylus-diameter");
    expectError(R"(<sphere name="s" centre="0 0 0" diameter="25" stylus-diameter="6" clearance="2" approach="4"><pose A="0"/></sphere>)",
                "clearance");
}

TEST(SpherePlan, APoseWhoseTouchesLeaveTheTravelIsNamed) {
    MeasurementPlan p = samplePlan();
    p.sphereRuns[0].centre = Vec3(490, 50, 40);  // X travel ends at 500: the +X ring touch of C = 0 cannot be reached
    try {
        sphereCommands(tableTable(), p.sphereRuns);
        FAIL() << "expected a travel error";
    } catch (const ModelError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("pose 0 (A=0 C=0) touch 1"), std::string::npos) << what;
        EXPECT_NE(what.find("axis X"), std::string::npos) << what;
        EXPECT_NE(what.find("travel"), std::string::npos) << what;
    }
}

TEST(SpherePlan, TouchPointsSitOnTheSphereAndEveryMoveBetweenPosesStaysClear) {
    // On the nominal machine the stylus ball centre at each target is `approach` inside the surface, at the approach
    // point `approach` outside, above it at R + clearance along the tool axis.
    const MachineModel& m = tableTable();
    const MeasurementPlan p = samplePlan();
    const SpherePlanCommands c = sphereCommands(m, p.sphereRuns);
    const Kinematics k(m);
    const SphereRun& r = p.sphereRuns[0];
    const Vec3 tip = stylusPoint(m, r);
    const double R = 15.5;
    EXPECT_EQ(c.poseCount(), 23);
    EXPECT_EQ(m.axisNames[static_cast<size_t>(c.parkAxis)], "Z");
    for (const SpherePoseCommand& pc : c.runs[0].poses) {
        EXPECT_NEAR((k.toolPointInWorkpiece(pc.safe, tip) - r.centre).norm(), R + r.clearance, 1e-9);
        ASSERT_EQ(pc.touches.size(), 5u);
        for (const SphereTouchCommand& t : pc.touches) {
            EXPECT_NEAR((k.toolPointInWorkpiece(t.approach, tip) - r.centre).norm(), R + r.approach, 1e-9);
            EXPECT_NEAR((k.toolPointInWorkpiece(t.target, tip) - r.centre).norm(), R - r.approach, 1e-9);
            EXPECT_GE((k.toolPointInWorkpiece(t.above, tip) - r.centre).norm(), R + r.clearance - 1e-9);
        }
        EXPECT_GT(c.parkValue, pc.safe[c.parkAxis]);
    }
}

// ---- the probe result file ---------------------------------------------------------------------------------------------

TEST(ProbeLog, WrittenAndReadBackGivesTheSameTouches) {
    const MachineModel& m = tableTable();
    const SpherePlanCommands c = sphereCommands(m, samplePlan().sphereRuns);
    const ProbeLog log = simulateSphereProbing(Kinematics(m), c);
    ASSERT_EQ(log.touches.size(), 115u);
    const ProbeLog back = parseProbeLog(formatProbeLog(log, m, 6), "x.txt", m);
    ASSERT_EQ(back.touches.size(), log.touches.size());
    for (size_t i = 0; i < log.touches.size(); ++i) {
        EXPECT_EQ(back.touches[i].pose, log.touches[i].pose);
        EXPECT_EQ(back.touches[i].touch, log.touches[i].touch);
        EXPECT_EQ(back.touches[i].triggered, 1);
        EXPECT_LT((back.touches[i].q - log.touches[i].q).cwiseAbs().maxCoeff(), 6e-7);
        EXPECT_EQ(back.touches[i].line, static_cast<int>(i) + 1);
    }
}

TEST(ProbeLog, MalformedLinesNameFileAndLine) {
    const MachineModel& m = tableTable();
    const auto expectError = [&](const std::string& text, int line, const std::string& what) {
        try {
            parseProbeLog(text, "log.txt", m);
            FAIL() << text;
        } catch (const InputError& e) {
            EXPECT_EQ(e.file(), "log.txt");
            EXPECT_EQ(e.line(), line) << e.what();
            EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
        }
    };
    expectError("header\nTOUCH 0 0 1.000000 1 2 3 0\n", 2, "words");
    expectError("TOUCH 0 0 1.000000 1 2 3 0 0 0\nTOUCH 0 1 1.000000 1 2 x 0 0 0\n", 2, "Z value 'x'");
    expectError("TOUCH 0 0.5 1.000000 1 2 3 0 0 0\n", 1, "touch '0.5'");
    expectError("TOUCH 0 0 0.5 1 2 3 0 0 0\n", 1, "flag");
    expectError("nothing here\n", 1, "no TOUCH line");
    // The controllers' number forms: Fanuc DPRNT "3." and leading blanks, a line without the flag.
    const ProbeLog ok = parseProbeLog("  TOUCH    3.    1.   12.5000  -3.2500  100.0000   45.000    0.000   90.000\n", "f", m);
    ASSERT_EQ(ok.touches.size(), 1u);
    EXPECT_EQ(ok.touches[0].pose, 3);
    EXPECT_EQ(ok.touches[0].triggered, -1);
    EXPECT_DOUBLE_EQ(ok.touches[0].q[m.axisIndex("X")], 12.5);
    EXPECT_NEAR(ok.touches[0].q[m.axisIndex("C")], 90 * kDeg, 1e-15);
}

/// A log of the sample plan on the nominal machine with one line replaced.
std::string logWith(const MachineModel& m, const SpherePlanCommands& c, size_t index, const std::function<void(ProbeTouch&)>& edit) {
    ProbeLog log = simulateSphereProbing(Kinematics(m), c);
    edit(log.touches[index]);
    return formatProbeLog(log, m, 6);
}

TEST(ProbeLog, MissedOutOfWindowDuplicatedAndMissingTouchesAreNamedNeverFitted) {
    const MachineModel& m = tableTable();
    const SpherePlanCommands c = sphereCommands(m, samplePlan().sphereRuns);
    const auto expectError = [&](const std::string& text, int line, const std::string& what) {
        try {
            sphereObservations(m, c, parseProbeLog(text, "probe.txt", m));
            FAIL() << "expected: " << what;
        } catch (const InputError& e) {
            EXPECT_EQ(e.file(), "probe.txt");
            EXPECT_EQ(e.line(), line) << e.what();
            EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
        }
    };
    // #5070 = 0 on line 13 (pose 2 touch 2).
    expectError(logWith(m, c, 12, [](ProbeTouch& t) { t.triggered = 0; }), 13, "pose 2 touch 2: missed");
    // The pole touch of pose 1 0.6 mm farther out than the nominal surface (window ±0.5 mm).
    expectError(logWith(m, c, 5, [&](ProbeTouch& t) { t.q[m.axisIndex("Z")] += 0.6; }), 6, "pose 1 touch 0: the stylus");
    // A log without the flag: a touch at the end of its probing move is a missed touch.
    {
        ProbeLog log = simulateSphereProbing(Kinematics(m), c);
        log.touches[4].q = c.runs[0].poses[0].touches[4].target;
        std::string text = formatProbeLog(log, m, 6);
        // "TOUCH 0 4 1.000000 X…" → "TOUCH 0 4 X…", as the Fanuc and HEIDENHAIN programs write it.
        std::string noFlag;
        std::istringstream in2(text);
        for (std::string l; std::getline(in2, l);) {
            std::istringstream w(l);
            std::vector<std::string> v;
            for (std::string s; w >> s;) v.push_back(s);
            v.erase(v.begin() + 3);
            std::string joined;
            for (const auto& s : v) joined += (joined.empty() ? "" : " ") + s;
            noFlag += joined + "\n";
        }
        expectError(noFlag, 5, "pose 0 touch 4: missed: the probe stopped at the end of its probing move");
    }
    // Pose 2 touch 2 logged at touch 1's contact (as LinuxCNC's stale DONE would repeat it): on the sphere, inside the
    // radial window, but 10+ mm off its own probing move.
    {
        const ProbeLog sim = simulateSphereProbing(Kinematics(m), c);
        expectError(logWith(m, c, 12, [&](ProbeTouch& t) { t.q = sim.touches[11].q; }), 13,
                    "pose 2 touch 2: the probe stopped");
    }
    // The rotary axes of another pose.
    expectError(logWith(m, c, 20, [&](ProbeTouch& t) { t.q[m.axisIndex("C")] += 1 * kDeg; }), 21, "axis C");
    // Twice the same touch; a touch the file does not have.
    expectError(logWith(m, c, 1, [](ProbeTouch& t) { t.touch = 0; }), 2, "recorded twice");
    expectError(logWith(m, c, 1, [](ProbeTouch& t) { t.pose = 99; }), 2, "poses 0 .. 22");
    {
        ProbeLog log = simulateSphereProbing(Kinematics(m), c);
        log.touches.pop_back();
        expectError(formatProbeLog(log, m, 6), 0, "pose 22 touch 4");
    }
}

// ---- identification -------------------------------------------------------------------------------------------------

DeviationSet locationTruth(const MachineModel& m) {
    DeviationSet d(m);
    d.set("EY0A", 18 * kUm);
    d.set("EZ0A", -12 * kUm);
    d.set("EB0A", 6 * kArcsec);
    d.set("EC0A", -8 * kArcsec);
    d.set("EX0C", 14 * kUm);
    d.set("EY0C", -9 * kUm);
    d.set("EA0C", 5 * kArcsec);
    d.set("EB0C", -7 * kArcsec);
    return d;
}

const char* const kEight[] = {"EY0A", "EZ0A", "EB0A", "EC0A", "EX0C", "EY0C", "EA0C", "EB0C"};

IdentifyOptions eightUnknowns(const MachineModel& m) {
    IdentifyOptions io;
    const DeviationSet d(m);
    for (const char* n : kEight) io.deviations.push_back(d.require(n));
    std::sort(io.deviations.begin(), io.deviations.end());
    return io;
}

TEST(SphereIdentification, NoiseFreeRoundTripRecoversTheEightLocationErrors) {
    // Round trip: simulate the sample plan on a machine with the eight location errors, a sphere mounted 30 µm off
    // and a trigger offset, identify (sphere offset and trigger as nuisances), recover the truth.
    const MachineModel& m = tableTable();
    MeasurementPlan p = samplePlan();
    p.sphereRuns[0].sphereOffset = Vec3(0.03, -0.02, 0.01);
    p.sphereRuns[0].triggerOffset = 0.004;
    const DeviationSet truth = locationTruth(m);
    const SpherePlanCommands c = sphereCommands(m, p.sphereRuns);
    const ProbeLog log = simulateSphereProbing(Kinematics(m, truth), c);
    const Observations obs = sphereObservations(m, c, log);
    const IdentificationResult res = identify(m, obs, eightUnknowns(m));
    for (const char* n : kEight) {
        const int i = truth.require(n);
        const double unit = m.deviations[static_cast<size_t>(i)].isAngle() ? kArcsec : kUm;
        EXPECT_NEAR(res.deviations.isoValue(i) / unit, truth.isoValue(i) / unit, 1e-6) << n;
    }
    EXPECT_NEAR(res.nuisance[0] / kUm, 30, 1e-6);
    EXPECT_NEAR(res.nuisance[1] / kUm, -20, 1e-6);
    EXPECT_NEAR(res.nuisance[2] / kUm, 10, 1e-6);
    EXPECT_EQ(res.report.rank, 11);
}

TEST(SphereIdentification, TheTriggerOffsetAndEZ0AAreOneCombination) {
    // With the trigger offset estimated (the default), EZ0A and the trigger move every centre the same way: the report
    // names the combination, the other seven are identified.
    const MachineModel& m = tableTable();
    MeasurementPlan p = samplePlan();
    p.sphereRuns[0].estimateTrigger = true;
    const SpherePlanCommands c = sphereCommands(m, p.sphereRuns);
    const Observations obs = sphereObservations(m, c, simulateSphereProbing(Kinematics(m, locationTruth(m)), c));
    const IdentificationResult res = identify(m, obs, eightUnknowns(m));
    EXPECT_EQ(res.report.rank, 11);
    EXPECT_EQ(res.report.unknowns, 12);
    ASSERT_EQ(res.report.identifiable.size(), 1u);
    EXPECT_NE(res.report.identifiable[0].text.find("EZ0A"), std::string::npos);
    EXPECT_NE(res.report.identifiable[0].text.find("trigger"), std::string::npos);
    const DeviationSet truth = locationTruth(m);
    EXPECT_NEAR(res.deviations.isoValue(truth.require("EX0C")) / kUm, 14, 0.01);
}

TEST(SphereIdentification, NoiseOfOneMicrometrePerTouchIntervalsCoverTheTruth) {
    // σ = 1 µm per touch (along each probing move), 100 trials with fixed seeds: each 95 % interval of the eight
    // location errors covers the truth in at least 90 of them.
    const MachineModel& m = tableTable();
    const MeasurementPlan p = samplePlan();
    const DeviationSet truth = locationTruth(m);
    const SpherePlanCommands c = sphereCommands(m, p.sphereRuns);
    const Kinematics k(m, truth);
    const IdentifyOptions io = eightUnknowns(m);
    std::map<std::string, int> covered;
    const int trials = 100;
    for (int t = 0; t < trials; ++t) {
        const Observations obs = sphereObservations(m, c, simulateSphereProbing(k, c, 1 * kUm, 1000 + t));
        const IdentificationResult res = identify(m, obs, io);
        for (const ParameterEstimate& e : res.report.parameters) {
            if (e.nuisance) continue;
            const double v = truth.isoValue(truth.require(e.name));
            covered[e.name] += e.lower95 <= v && v <= e.upper95;
        }
    }
    ASSERT_EQ(covered.size(), 8u);
    for (const auto& [name, n] : covered) EXPECT_GE(n, 90) << name << " covered in " << n << " of " << trials;
}

}  // namespace
}  // namespace cnccomp
