#pragma once
// Console tables shared by the subcommands.
#include "cnccomp/deviations.hpp"

namespace cnccomp::cli {

/// Prints the present deviations (um / arcsec); with `truth`, also the truth and the difference.
/// Returns the largest |difference| in (um, arcsec).
std::pair<double, double> printDeviations(const DeviationSet& d, const DeviationSet* truth);

}  // namespace cnccomp::cli
