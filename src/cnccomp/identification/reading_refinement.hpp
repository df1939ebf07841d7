#pragma once
// Refinement of the papers' formula readings on the exact model (seeds 001 and 003). The formulas turn measured
// data into readings F (one per identified error) assuming every other error absent; the readings of the real data
// mix the errors to first order. With G = ∂F(simulate(θ))/∂θ taken once on the nominal machine (central
// differences), Gauss–Newton  θ ← θ + G⁻¹ (F(measured) − F(simulate(θ)))  finds the errors whose simulated data
// give the same readings as the measurement; the first step is the first-order decoupling of the formulas.
#include <functional>
#include <vector>

#include <Eigen/Core>

#include "cnccomp/deviations.hpp"

namespace cnccomp::identification {

/// `readings(set)`: the formulas applied to the data simulated with `set` (size = devs.size(), internal units).
/// Returns θ after `steps` Gauss–Newton steps from θ = measured readings (steps = 0: the plain formulas).
/// Throws ModelError when G is singular (the readings cannot tell the errors apart).
DeviationSet refineReadings(const MachineModel& m, const std::vector<int>& devs,
                            const std::function<Eigen::VectorXd(const DeviationSet&)>& readings,
                            const Eigen::VectorXd& measured, int steps);

}  // namespace cnccomp::identification
