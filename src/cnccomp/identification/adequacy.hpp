#pragma once
// Model adequacy: after a least-squares fit, is the residual what the data's noise can give, or does the model lack
// something? Without this test a fit that absorbs missing errors into the ones it has (e.g. the C table's error
// motions of a DBB5 plan taken up by the squareness and location errors) reports tight intervals that miss the truth.
//
// Per run, the noise of one sample is estimated from the data, in this order:
//  1. passes: samples at equal sweep angles (CW and CCW passes, repeated runs): pooled variance within each angle;
//  2. stated: the instrument's stated noise (<plan noise-um="…">);
//  3. successive differences (von Neumann, "Distribution of the ratio of the mean square successive difference to the
//     variance", Ann. Math. Statist. 12 (1941)): σ² ≈ Σ (r_{i+1} − r_i)² / (2(n − 1)) along the sweep, which a smooth
//     systematic residual hardly raises; floored at the quantisation noise q/√12 of a q = 0.1 µm resolution [G].
// The run's statistic F = (Σ r² / dof) / σ², dof = its share n·(m − rank)/m of the fit's redundancy, is compared with the
// F(dof, noise dof) quantile (Paulson's normal approximation, Biometrika 1942; noise dof = angle repeats, ∞ for a
// stated noise, 2(n − 1)/3 for successive differences) at 1 − 0.001 / runs (Bonferroni), and the overall F at 99.9 %.
// The residual of each run with a sweep is fitted with orders 0–6 of the sweep angle; a failed run whose orders 2–6
// carry most of its residual points at the error motions (component errors) of the rotary axes that turn in it.
// When the model does not fit, the stddev and the 95 % intervals (already scaled with σ̂ = σ·√F) are widened by the
// residual's lag-1 autocorrelation ρ (pooled within runs): factor √((1 + ρ)/(1 − ρ)), the variance inflation of the mean of
// an AR(1) series (Bayley & Hammersley, "The effective number of independent observations in an autocorrelated time
// series", JRSS Suppl. 8 (1946)): correlated residuals carry fewer independent samples than their count.
#include "cnccomp/identification/lsq.hpp"
#include "cnccomp/identification/problem.hpp"

namespace cnccomp::identification {

/// Fills report.adequacy from the residual at scaled point x; when the model does not fit, puts the warning first in
/// report.warnings and widens stddev / intervals / covariance of the parameters and combinations.
void testAdequacy(const LsqProblem& problem, const Eigen::VectorXd& x, const IdentifyOptions& options,
                  IdentificationReport& report);

/// Quantile of the F(d1, d2) distribution (Paulson's approximation; d2 ≥ 1e6 taken as ∞: χ²(d1)/d1 by Wilson–Hilferty).
double fQuantile(double p, double d1, double d2);

}  // namespace cnccomp::identification
