#pragma once
// JSON report of the circles of the linear axes (`identify --report R.json` on a plan of <circle> runs), schema
// "cnccomp-linear-circles/1": per run the test conditions, the ISO 230-4 figures per pass (G, F max / min, mean
// radius) and of the run (G, H), the fit (samples, unknowns, rank, σ̂), every diagnostic ranked by its share of the
// circularity (value, unit, 95 % interval, circularity it makes alone, share %, the source of its model), every
// parameter with the nuisance (centring per pass, radius offset), the confounded groups and their identifiable
// combinations; then the deviations written into the deviation set and the notes on what was not. Lengths µm (ISO
// figures µm, radii mm), angles deg, unknown values null.
#include <string>

#include "cnccomp/linear_circle_identify.hpp"

namespace cnccomp::io {

std::string formatLinearCircleJson(const std::string& machine, const LinearCircleIdentification& id);

}  // namespace cnccomp::io
