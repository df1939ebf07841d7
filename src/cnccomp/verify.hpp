#pragma once
// Verification (DESIGN data flow, step 5): the ball-bar runs of a plan re-simulated on the true machine, without and
// with a compensation, side by side.
#include <string>
#include <vector>

#include "cnccomp/ballbar.hpp"

namespace cnccomp {

/// Builds the command map of a compensation for one run (the run fixes the tool length, RB).
using CompensationFactory = std::function<CommandMap(const BallbarRun&)>;

/// Ideal model-based compensation (what a TCP controller or `cnccomp correct` does with an identified set): the
/// commands that put the tool of the `identified` machine where the nominal machine would have it (eq. (7) inverted
/// by Newton). Commands where the solver does not converge are passed through unchanged.
CompensationFactory modelCompensation(const Kinematics& nominal, const Kinematics& identified);

struct VerifyRow {
    std::string run;
    BallbarTest test = BallbarTest::BX;
    Vec3 eccentricityBefore, eccentricityAfter;  ///< mm, NaN out of plane
    double spanBefore = 0, spanAfter = 0;        ///< max ΔL − min ΔL, mm
};

/// Simulates every run of `runs` on `truth`, once as programmed and once through `compensation`.
std::vector<VerifyRow> verifyRuns(const Kinematics& truth, const std::vector<BallbarRun>& runs,
                                  const CompensationFactory& compensation);

}  // namespace cnccomp
