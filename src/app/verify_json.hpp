#pragma once
// The verification result as JSON (schema "cnccomp-verify/1"): per run and pass the ΔL traces before and after
// (µm), ISO 230-4 circular deviation G, radial deviation F (max, min), mean radial error, circle centre, eccentricity;
// R-test displacements; the volumetric figures and the deviations left. Lengths in µm, angles in degrees (sweep) and
// arcseconds (tool-axis tilt); NaN is written as null. For `cnccomp verify --json` (staged with the HTML report).
#include <optional>
#include <string>

#include "app/verify.hpp"

namespace cnccomp::app {

/// The gates of `cnccomp verify`: the residual (largest ΔL span after) at most `gateUm`, and the volumetric tool-tip
/// error after at most `volumetricGateUm` (failed when there is no volumetric figure). Unset gates pass.
bool verifyGatePassed(const VerifyResult& result, std::optional<double> gateUm, std::optional<double> volumetricGateUm);
/// `gateUm`, `volumetricGateUm`: the --max-residual-um / --max-volumetric-um gates, if any. `passed` is true when
/// every gate given holds and the compensation does not make the machine worse (`makes_machine_worse`, `worse`:
/// VerifyResult::worse, always checked); `remaining` lists each deviation left under the backend's name with its ISO
/// name and ISO value, and the paper alias with the alias' value (VerifyRemaining).
std::string formatVerifyJson(const VerifyResult& result, std::optional<double> gateUm = std::nullopt,
                             std::optional<double> volumetricGateUm = std::nullopt);

}  // namespace cnccomp::app
