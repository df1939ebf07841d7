#pragma once
// Console tables shared by the subcommands.
#include "cnccomp/deviations.hpp"

namespace cnccomp::cli {

/// Prints the present location deviations under their ISO names (ISO values, um / arcsec; the alias column names the
/// paper symbol); with `truth`, also the truth and the difference.
/// Returns the largest |difference| in (um, arcsec).
std::pair<double, double> printDeviations(const DeviationSet& d, const DeviationSet* truth);

}  // namespace cnccomp::cli
