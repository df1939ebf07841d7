#pragma once
// Least squares in two stages: what the runs that move only linear axes determine is fitted from them alone, then held
// while the rest is fitted to every run.
//
// Why. A plan that holds circles of the linear axes (the DBB5 XY, YZ and ZX circles, Ibaraki et al. 2011, eq. (1)–(2))
// determines the linear axes' squareness from those runs alone; the rotary runs see the squareness too, mixed with the
// rotary axes' location errors and with whatever the model lacks (an error motion of the table). Fitted together, the
// squareness absorbs part of what is missing from the rotary runs: on the DBB5 B/C sample with C error motions of
// 4–6 µm, EB0Z came out 3.86″ for a true 6.00″ and EC0Y −4.27″ for −3.00″. Fitted first from the circles of the
// linear axes, they are 5.9″ and −3.0″ whatever the rotary runs hold (tests/core/identification/test_lsq_staged_fit.cpp).
//
// How.
//  1. Stage 1: the runs whose observation says movesOnlyLinearAxes() are fitted alone with every requested deviation;
//     the deviations identified there (every coefficient identified: the others have no effect on those runs or are
//     confounded in them) are the stage-1 deviations.
//  2. Stage 2: every run (the linear circles included) is fitted with the other requested deviations, the stage-1
//     deviations held at their stage-1 values.
//  3. Uncertainty: the stage-2 estimate θ₂ depends on the held values θ₁; its covariance is
//     Cov(θ₂) = Cov(θ₂ | θ₁) + G Cov(θ₁) Gᵀ, G = ∂θ₂/∂θ₁, with G from one more stage-2 fit per stage-1 unknown moved
//     by its standard deviation (central-free forward difference; a Gauss–Newton step of a well-posed problem is
//     linear over one σ). The cross covariance is G Cov(θ₁). Intervals widen by the same factor as their standard
//     deviation (the Student t quantile and the adequacy inflation of stage 2 are kept). Monte Carlo intervals, when
//     asked, are each stage's own (the stage-2 ones conditional on θ₁).
// One stage (identify() as it is) when the plan has no such run, no other run, when stage 1 identifies none of the
// requested deviations or all of them, or when `options.staged` is false (`identify --one-stage`).
#include "cnccomp/identification/lsq.hpp"

namespace cnccomp::identification {

/// identify() in two stages as above; the report's `stages` says which deviations came from which runs.
IdentificationResult identifyStaged(const MachineModel& machine, const Observations& observations,
                                    const IdentifyOptions& options = {});

}  // namespace cnccomp::identification
