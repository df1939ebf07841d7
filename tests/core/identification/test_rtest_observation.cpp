// Analytic Jacobians of the observation kinds of seeds 001–004 (R-test displacements, DBB5 ΔL, absolute ball-bar
// ΔL) against central finite differences of their predictions, at a point with location and component errors.
#include <gtest/gtest.h>

#include "cnccomp/identification/dbb5_observation.hpp"
#include "cnccomp/identification/problem.hpp"
#include "cnccomp/identification/rtest_observation.hpp"
#include "cnccomp/identification/absolute_ballbar_observation.hpp"
#include "cnccomp/identification/tilting_head_errors.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "jacobian_check.hpp"
#include "test_support.hpp"

namespace cnccomp {
using namespace cnccomp::identification;
using namespace cnccomp::io;
using namespace cnccomp::measurement;
namespace {

const MachineModel& tableTable() { return test::sampleMachine("table-table-ac"); }

using test::jacobianMismatch;

DeviationSet mixedErrors(const MachineModel& m) {
    // The sample truths of seeds 001 and 004 together: location, squareness and component tables.
    DeviationSet d = readDeviationCsv(test::sourcePath("samples/deviations/table-table-ac-truth.csv"), m);
    const DeviationSet k = readDeviationCsv(test::sourcePath("samples/deviations/table-table-ac-kinematic.csv"), m);
    for (size_t i = 0; i < m.deviations.size(); ++i)
        if (m.deviations[i].kind == DeviationKind::Component) {
            const auto& def = m.deviations[i];
            d.values.segment(def.offset, def.size()) = k.values.segment(def.offset, def.size());
        }
    return d;
}

TEST(RtestObservationJacobian, MatchesFiniteDifferences) {
    const MachineModel& m = tableTable();
    const DeviationSet at = mixedErrors(m);
    MeasurementPlan p = readPlanXml(test::sourcePath("samples/plans/table-table-ac-rtest.xml"));
    std::vector<RtestRun> runs = {p.rtestRuns[4]};  // XYZAC: every axis moves
    runs[0].steps = 9;
    runs[0].estimateBall = true;
    runs[0].ballOffset = Vec3(0.01, -0.02, 0.005);
    const Observations obs = rtestObservations(m, runs, {simulateRtest(Kinematics(m, at), runs[0])});
    EXPECT_EQ(obs[0]->nuisanceCount(), 3);
    EXPECT_LT(jacobianMismatch(m, obs, at), 1e-6);
}

TEST(Dbb5ObservationJacobian, MatchesFiniteDifferences) {
    const MachineModel& m = tableTable();
    const DeviationSet at = mixedErrors(m);
    const MeasurementPlan p = readPlanXml(test::sourcePath("samples/plans/dbb5-table-table-ac.xml"));
    std::vector<Dbb5Run> runs = {p.dbb5Runs[2], p.dbb5Runs[3], p.dbb5Runs[9]};  // ZX circle, C and A circles
    std::vector<BallbarTrace> traces;
    for (Dbb5Run& r : runs) {
        r.stepDeg = 40;
        traces.push_back(simulateDbb5(Kinematics(m, at), r));
    }
    EXPECT_LT(jacobianMismatch(m, dbb5Observations(m, runs, traces), at), 1e-6);
}

TEST(AbsoluteBallbarObservationJacobian, MatchesFiniteDifferences) {
    const MachineModel m = readMachineXml(test::sourcePath("samples/machines/tilting-head-b.xml"));
    const DeviationSet at = readDeviationCsv(test::sourcePath("samples/deviations/tilting-head-b-truth.csv"), m);
    const MeasurementPlan p = readPlanXml(test::sourcePath("samples/plans/tilting-head-b-patterns.xml"));
    std::vector<BallbarRun> runs = {p.absoluteRuns[0], p.absoluteRuns[3], p.absoluteRuns[4]};
    runs[1].estimateWorkBallOffset = true;
    std::vector<BallbarTrace> traces;
    for (const BallbarRun& r : runs) traces.push_back(simulateAbsoluteRun(Kinematics(m, at), r));
    EXPECT_LT(jacobianMismatch(m, absoluteBallbarObservations(m, runs, traces), at), 1e-6);
}

}  // namespace
}  // namespace cnccomp
