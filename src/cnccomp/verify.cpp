#include "cnccomp/verify.hpp"

#include <algorithm>

#include "cnccomp/inverse_kinematics.hpp"

namespace cnccomp {

CompensationFactory modelCompensation(const Kinematics& nominal, const Kinematics& identified) {
    return [&nominal, &identified](const BallbarRun& run) -> CommandMap {
        const Vec3 tip = nominal.toolPoint(run.RB);
        return [&nominal, &identified, tip](const AxisVector& q) {
            const IkResult r = solveToolPose(identified, toolPose(nominal, q, tip), tip, q);
            return r.converged ? r.q : q;
        };
    };
}

std::vector<VerifyRow> verifyRuns(const Kinematics& truth, const std::vector<BallbarRun>& runs,
                                  const CompensationFactory& compensation) {
    const auto span = [](const BallbarTrace& t) {
        const auto [lo, hi] = std::minmax_element(t.dL.begin(), t.dL.end());
        return *hi - *lo;
    };
    std::vector<VerifyRow> rows;
    for (const BallbarRun& run : runs) {
        const BallbarTrace before = simulateRun(truth, run);
        const BallbarTrace after = simulateRun(truth, run, compensation(run));
        rows.push_back({run.name, run.test, traceEccentricity(truth.machine(), run, before),
                        traceEccentricity(truth.machine(), run, after), span(before), span(after)});
    }
    return rows;
}

}  // namespace cnccomp
