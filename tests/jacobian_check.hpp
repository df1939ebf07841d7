#pragma once
// Finite-difference check of an identification problem's analytic Jacobian: every deviation of the machine as an
// unknown, evaluated at `at`.
#include <vector>

#include <gtest/gtest.h>

#include "cnccomp/identification/problem.hpp"

namespace cnccomp::test {

/// Largest |analytic − central difference| over the largest |central difference| (1e-2 µm / arcsec steps).
inline double jacobianMismatch(const MachineModel& m, const identification::Observations& obs, const DeviationSet& at) {
    std::vector<int> devs;
    for (int i = 0; i < static_cast<int>(m.deviations.size()); ++i) devs.push_back(i);
    const identification::UnknownLayout layout(m, devs, obs);
    const identification::LsqProblem p(m, obs, layout, at);
    Eigen::MatrixXd Ja, Jn;
    p.jacobian(p.start(), Ja);
    p.numericJacobian(p.start(), Jn, 1e-2);
    EXPECT_GT(Ja.norm(), 0);
    return (Ja - Jn).cwiseAbs().maxCoeff() / Jn.cwiseAbs().maxCoeff();
}

}  // namespace cnccomp::test
