// Verification: compensating with the true set removes the ball-bar errors; with the closed-form estimate it removes
// nearly all of them; the uncompensated run reproduces simulateRun.
#include <gtest/gtest.h>

#include "cnccomp/closed_form.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "cnccomp/verify.hpp"
#include "test_support.hpp"

namespace cnccomp {
namespace {

TEST(Verify, CompensationWithTheTruthFlattensEveryRun) {
    const MachineModel& m = test::multitasking();
    const DeviationSet truth = readDeviationCsv(test::sourcePath("samples/deviations/multitasking-truth.csv"), m);
    MeasurementPlan plan = readPlanXml(test::sourcePath("samples/plans/multitasking-six-circles.xml"));
    for (auto& r : plan.runs) r.stepDeg = 10;
    const Kinematics nominal(m), actual(m, truth);
    const auto rows = verifyRuns(actual, plan.runs, modelCompensation(nominal, actual));
    ASSERT_EQ(rows.size(), plan.runs.size());
    for (const auto& r : rows) {
        EXPECT_GT(r.spanBefore, 1e-3) << r.run;  // micrometres of error before
        EXPECT_LT(r.spanAfter, 1e-8) << r.run;   // nothing left after
    }
}

TEST(Verify, ClosedFormEstimateRemovesMostOfTheError) {
    const MachineModel& m = test::multitasking();
    const DeviationSet truth = readDeviationCsv(test::sourcePath("samples/deviations/multitasking-truth.csv"), m);
    MeasurementPlan plan = readPlanXml(test::sourcePath("samples/plans/multitasking-six-circles.xml"));
    for (auto& r : plan.runs) r.stepDeg = 5;
    const Kinematics nominal(m), actual(m, truth);
    std::vector<BallbarTrace> traces;
    for (const auto& r : plan.runs) traces.push_back(simulateRun(actual, r));
    const DeviationSet id = identifyClosedForm(m, eccentricitiesFromTraces(m, plan.runs, traces));
    const Kinematics model(m, id);
    for (const auto& r : verifyRuns(actual, plan.runs, modelCompensation(nominal, model))) {
        // γXY (3″) is not identified by the closed form and stays: its C-radial signature is a 2nd harmonic.
        EXPECT_LT(r.spanAfter, 0.1 * r.spanBefore + 0.2e-3) << r.run;
        for (int c = 0; c < 3; ++c)
            if (std::isfinite(r.eccentricityAfter[c])) {
                EXPECT_LT(std::abs(r.eccentricityAfter[c]), 0.05e-3) << r.run << " e" << "xyz"[c];
            }
    }
}

}  // namespace
}  // namespace cnccomp
