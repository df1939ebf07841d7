#pragma once
// The DBB5 measurement equivalent to the cone-frustum machining test (NAS 979; ISO 10791-7, cited by the paper as
// ISO/DIS 10791-7:2012) — Ibaraki et al., "Identification of motion error sources on five-axis machine tools by
// ball-bar measurements (1st report)", section 4.4, Fig. 11; after B. Hong, S. Ibaraki, A. Matsubara, "Influence of
// position-dependent geometric errors of rotary axes on a machining test of cone frustum by five-axis machine tools",
// Precision Engineering 35 (2011).
//
// In the workpiece frame the cone axis n = R_y(tilt)·z passes through the table ball (the frustum's base inclined by
// `tilt` about the workpiece Y, 10° in NAS 979). At azimuth φ about n the tool axis (tip → spindle) lies along the
// cone's generatrix, leaning towards n by the half apex angle τ (15° in NAS 979):
//   t(φ) = R_y(tilt)·(−sin τ cos φ, −sin τ sin φ, cos τ),
// and the spindle ball sits on the bar, inclined by ζ from n (the DBB5 holds its balls at 45°):
//   p(φ) = ball + LB·R_y(tilt)·(sin ζ cos φ, sin ζ sin φ, cos ζ).
// So both rotary axes move with the linear ones, as when the frustum is cut; the bar reads the tool's error along
// the bar. [G: the paper gives no formula; this parametrisation follows its Fig. 11 (bar at 45°, spindle ball on a
// circle about the table ball) and NAS 979's cone.]
//
// The rotary commands that turn a tilting rotary table (two rotary axes on the workpiece side, none on the tool side)
// to a tool direction are closed form (two Paden–Kahan subproblems): the outer angle q1 keeps the inner axis'
// component of the tool direction, q1 = δ ± acos(…); the branch is the one with the smaller |q1| at the run's
// setup angle, kept over the sweep so the commands are continuous.
#include <optional>

#include "cnccomp/identification/dbb5_circular.hpp"
#include "cnccomp/identification/dbb5_run.hpp"

namespace cnccomp::identification {

/// Tool axis t(φ) (tip → spindle) and bar direction u(φ) (table ball → spindle ball), workpiece frame, unit.
Vec3 dbb5ConeToolAxis(const measurement::Dbb5Run& run, double phiDeg);
Vec3 dbb5ConeBarDirection(const measurement::Dbb5Run& run, double phiDeg);

/// Commands of the two table rotary axes (the rest of `q` untouched) that put the machine's tool direction along
/// `toolAxisW` (tip → spindle, workpiece frame) on the nominal machine; `branch` +1 / −1 picks the solution.
/// Throws ModelError when the machine is not a tilting rotary table or the direction cannot be reached.
AxisVector dbb5TableOrientation(const MachineModel& m, const Vec3& toolAxisW, int branch, AxisVector q);

/// The branch dbb5TableOrientation takes for a cone-frustum run: the smaller outer tilt at the setup angle.
int dbb5ConeBranch(const MachineModel& m, const measurement::Dbb5Run& run);

struct Dbb5ConeEvaluation {
    std::string run;
    CircularTestResult iso;          ///< ISO 230-4 figures of the measured profile over φ
    std::optional<BallbarTrace> predicted;  ///< the run simulated with a deviation set (when given)
    double rmsDifference = 0, maxDifference = 0;  ///< measured − predicted, mm (when predicted)
};

/// ISO 230-4 figures of a cone-frustum run; with `deviations`, also the profile they predict and the difference —
/// the check of identified errors against a five-axis test the identification did not use (the paper's use).
Dbb5ConeEvaluation evaluateDbb5ConeRun(const MachineModel& m, const measurement::Dbb5Run& run, const BallbarTrace& trace,
                                       const DeviationSet* deviations = nullptr);

}  // namespace cnccomp::identification
