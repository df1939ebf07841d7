// The DBB5 measurement equivalent to the cone-frustum test (NAS 979 / ISO 10791-7; Ibaraki et al., 1st report,
// section 4.4): its commands checked by forward kinematics (tool axis along the cone's generatrix, spindle ball on
// the bar) on both tilting tables, its analytic Jacobian against finite differences, and its use as the check of
// identified errors: it predicts within round-off what the identification saw, and shows what it could not see (the
// angular positioning error of C, invisible to the on-axis runs).
#include <gtest/gtest.h>

#include <cmath>

#include "cnccomp/error.hpp"
#include "cnccomp/identification/dbb5_component_errors.hpp"
#include "cnccomp/identification/dbb5_cone_frustum.hpp"
#include "cnccomp/identification/dbb5_location_errors.hpp"
#include "cnccomp/identification/dbb5_observation.hpp"
#include "cnccomp/identification/problem.hpp"
#include "cnccomp/inverse_kinematics.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "jacobian_check.hpp"
#include "test_dbb5_support.hpp"

namespace cnccomp {
using namespace cnccomp::identification;
using namespace cnccomp::io;
using namespace cnccomp::measurement;
namespace {

const MachineModel& bc() { return test::tableTableBc(); }
const MeasurementPlan& plan() { return test::dbb5PlanBc(); }
const Dbb5Run& cone() { return test::dbb5RunBc("cone"); }

TEST(Dbb5ConeFrustum, CommandsPutToolAndBallOnTheCone) {
    static const MachineModel ac = readMachineXml(test::sourcePath("samples/machines/table-table-ac.xml"));
    for (const MachineModel* m : {&bc(), &ac}) {
        const Kinematics nominal(*m);
        const Dbb5Run& r = cone();
        const Vec3 tip = nominal.toolPoint(r.toolLength);
        const int outer = m->requireAxis(m == &ac ? "A" : "B"), inner = m->requireAxis("C");
        AxisVector previous;
        for (double phi : r.anglesDeg()) {
            const AxisVector q = dbb5Commands(*m, r, phi);
            const ToolPose p = toolPose(nominal, q, tip);
            EXPECT_LT((p.axis + dbb5ConeToolAxis(r, phi)).norm(), 1e-12) << m->name << " " << phi;
            EXPECT_LT((p.tip - (r.ball + r.LB * dbb5ConeBarDirection(r, phi))).norm(), 1e-9) << m->name << " " << phi;
            // The tool axis leans from the cone axis by 15° and the cone axis from Z by 10°: the table tilts 5°…25°.
            EXPECT_LE(std::abs(q[outer]), 25 * kDeg + 1e-9);
            EXPECT_GE(std::abs(q[outer]), 5 * kDeg - 1e-9);
            if (previous.size()) {  // continuous: no branch switch over the turn
                EXPECT_LT(std::abs(q[outer] - previous[outer]), 5 * kDeg) << phi;
                EXPECT_LT(std::abs(std::remainder(q[inner] - previous[inner], 2 * kPi)), 30 * kDeg) << phi;  // 5° tool tilt: C moves fast
            }
            previous = q;
        }
        for (double v : simulateDbb5(nominal, r).dL) EXPECT_LT(std::abs(v), 1e-10);
    }
    // The geometry itself: unit vectors at the stated angles from the tilted cone axis.
    const Dbb5Run& r = cone();
    const Vec3 n = Eigen::AngleAxisd(10 * kDeg, Vec3::UnitY()) * Vec3::UnitZ();
    EXPECT_NEAR(std::acos(dbb5ConeToolAxis(r, 123).dot(n)), 15 * kDeg, 1e-12);
    EXPECT_NEAR(std::acos(dbb5ConeBarDirection(r, 123).dot(n)), 45 * kDeg, 1e-12);
    EXPECT_THROW(dbb5Commands(test::multitasking(), r, 0), ModelError);  // no tilting table
}

TEST(Dbb5ConeFrustum, JacobianMatchesFiniteDifferences) {
    const MachineModel& m = bc();
    const DeviationSet at = test::dbb5TruthBc();
    Dbb5Run r = cone();
    r.stepDeg = 30;
    const Observations obs = dbb5Observations(m, {r}, {simulateDbb5(Kinematics(m, at), r)});
    EXPECT_LT(test::jacobianMismatch(m, obs, at), 1e-6);
}

TEST(Dbb5ConeFrustum, ChecksTheIdentifiedErrors) {
    // Truth: the sample location errors, plus an angular positioning error of C (ECC table, ±4 arcsec) that the
    // on-axis C runs cannot see. Identified from every run but the cone (location refined, C component tables): the
    // cone's profile predicted from them misses exactly ECC's share, which the cone run shows.
    const MachineModel& m = bc();
    DeviationSet truth = test::dbb5TruthBc();
    const DeviationDef& ecc = m.deviations[static_cast<size_t>(m.deviationIndex("ECC"))];
    const double c[12] = {0, 3, 4, 2, -1, -3, -4, -2, 1, 3, 2, 1};
    for (int k = 0; k < 12; ++k) truth.values[ecc.offset + k] = c[k] * kArcsec;
    std::vector<Dbb5Run> runs;
    std::vector<BallbarTrace> traces;
    const Kinematics k(m, truth);
    for (const Dbb5Run& r : plan().dbb5Runs)
        if (r.kind != Dbb5Run::Kind::ConeFrustum) {
            runs.push_back(r);
            traces.push_back(simulateDbb5(k, r));
        }
    const Dbb5LocationResult loc = dbb5LocationErrors(m, runs, traces);
    const DeviationSet identified =
        dbb5ComponentTables(m, dbb5ComponentProfile(m, runs, traces, loc.deviations, "C"), loc.deviations);
    const BallbarTrace measured = simulateDbb5(k, cone());
    const Dbb5ConeEvaluation e = evaluateDbb5ConeRun(m, cone(), measured, &identified);
    ASSERT_TRUE(e.predicted.has_value());
    // ECC's own share of the profile: the run on a machine with ECC only.
    DeviationSet onlyEcc(m);
    onlyEcc.values.segment(ecc.offset, 12) = truth.values.segment(ecc.offset, 12);
    const BallbarTrace share = simulateDbb5(Kinematics(m, onlyEcc), cone());
    double rmsShare = 0, worstMismatch = 0;
    for (size_t i = 0; i < share.dL.size(); ++i) {
        rmsShare += share.dL[i] * share.dL[i];
        worstMismatch = std::max(worstMismatch, std::abs(measured.dL[i] - e.predicted->dL[i] - share.dL[i]));
    }
    rmsShare = std::sqrt(rmsShare / static_cast<double>(share.dL.size()));
    std::printf("[ dbb5 cone ] circularity %.3f um; measured - predicted: rms %.4f um (ECC alone %.4f um), "
                "worst mismatch to ECC's share %.5f um\n",
                e.iso.circularity / kUm, e.rmsDifference / kUm, rmsShare / kUm, worstMismatch / kUm);
    EXPECT_GT(rmsShare, 0.05 * kUm);
    EXPECT_NEAR(e.rmsDifference, rmsShare, 0.01 * rmsShare);
    EXPECT_LT(worstMismatch, 0.002 * kUm);
    // Without ECC the prediction matches the measurement.
    const Dbb5ConeEvaluation ok = evaluateDbb5ConeRun(
        m, cone(), simulateDbb5(Kinematics(m, test::dbb5TruthBc()), cone()),
        &identified);
    EXPECT_LT(ok.maxDifference, 0.003 * kUm);
    EXPECT_THROW(evaluateDbb5ConeRun(m, plan().dbb5Runs[0], measured), ModelError);
}

TEST(Dbb5ConeFrustum, PlanRoundTripAndErrors) {
    // The B/C plan written and read back keeps every run (kinds, cone angles); bad cone attributes name file and line.
    test::ScratchDir dir("dbb5-cone-plan");
    writePlanXml(dir.file("p.xml"), plan());
    const MeasurementPlan back = readPlanXml(dir.file("p.xml"));
    ASSERT_EQ(back.dbb5Runs.size(), plan().dbb5Runs.size());
    for (size_t i = 0; i < back.dbb5Runs.size(); ++i) {
        const Dbb5Run &a = back.dbb5Runs[i], &b = plan().dbb5Runs[i];
        EXPECT_EQ(a.name, b.name);
        EXPECT_EQ(a.kind, b.kind);
        EXPECT_EQ(a.ball, b.ball);
        EXPECT_EQ(a.coneTiltDeg, b.coneTiltDeg);
        EXPECT_EQ(a.toolAngleDeg, b.toolAngleDeg);
        EXPECT_EQ(a.barAngleDeg, b.barAngleDeg);
        EXPECT_EQ(a.anglesDeg(), b.anglesDeg());
    }
    EXPECT_EQ(cone().coneTiltDeg, 10);
    EXPECT_EQ(cone().toolAngleDeg, 15);
    EXPECT_EQ(cone().barAngleDeg, 45);
    const std::string f = dir.file("bad.xml");
    const auto expectError = [&](const std::string& run, const std::string& text) {
        test::writeText(f, "<plan>\n" + run + "\n</plan>\n");
        try {
            readPlanXml(f);
            ADD_FAILURE() << "expected an InputError for " << run;
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find(f + ":2"), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
        }
    };
    expectError("<dbb5 name=\"c\" kind=\"cone\" LB=\"100\" ball=\"0 0 0\" tool-angle=\"95\"/>", "tool angle");
    expectError("<dbb5 name=\"c\" kind=\"cone\" LB=\"100\" ball=\"0 0 0\" bar-angle=\"0\"/>", "bar angle");
    expectError("<dbb5 name=\"c\" kind=\"cone\" LB=\"100\" ball=\"0 0 0\" cone-tilt=\"nan\"/>", "cone-tilt");
    expectError("<dbb5 name=\"c\" kind=\"conic\" LB=\"100\" ball=\"0 0 0\"/>", "linear, rotary or cone");
}

}  // namespace
}  // namespace cnccomp
