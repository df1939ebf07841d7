#pragma once
// Eccentricity table: one row per ball-bar run (the input of the closed-form method of [MultiTasking]).
#include <limits>
#include <string>
#include <vector>

#include "cnccomp/ballbar.hpp"

namespace cnccomp {

struct EccentricityRow {
    BallbarTest test = BallbarTest::BX;
    double LB = 0, RB = 0, RC = 0, ZC = 0;  ///< mm
    Vec3 e = Vec3::Constant(std::numeric_limits<double>::quiet_NaN());  ///< mm; NaN = empty cell
    std::string source;  ///< "file:line" or run name, for error messages
};

/// Fits the eccentricity of every run of a plan from its trace (same order).
std::vector<EccentricityRow> eccentricitiesFromTraces(const MachineModel& m, const std::vector<BallbarRun>& runs,
                                                      const std::vector<BallbarTrace>& traces);

}  // namespace cnccomp
