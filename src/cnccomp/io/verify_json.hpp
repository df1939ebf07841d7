#pragma once
// The verification result as JSON (schema "cnccomp-verify/1"): per run and pass the ΔL traces before and after
// (µm), ISO 230-4 circular deviation G, radial deviation F (max, min), mean radial error, circle centre, eccentricity;
// R-test displacements; the volumetric figures and the deviations left. Lengths in µm, angles in degrees (sweep) and
// arcseconds (tool-axis tilt); NaN is written as null. For `cnccomp verify --json` (staged with the HTML report).
#include <optional>
#include <string>

#include "cnccomp/verify.hpp"

namespace cnccomp {

/// `gateUm`: the --max-residual-um gate, if any (the JSON says whether it passed).
std::string formatVerifyJson(const VerifyResult& result, std::optional<double> gateUm = std::nullopt);

}  // namespace cnccomp
