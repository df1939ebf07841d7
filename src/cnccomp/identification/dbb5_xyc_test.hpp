#pragma once
// The XYC test of ISO 10791-6 as the DBB5 paper uses it (Ibaraki et al., 1st report, section 4.2.3, Fig. 8,
// eq. (4)–(5); the paper cites it as ISO/DIS 10791-6:2012 Annex K2 [G: the annex text itself was not available]):
// the rotary table turns a full circle with the table ball at radius R from its axis while X and Y follow, the bar
// along the table axis (spindle ball straight above the table ball). A tilt of the table axis relative to the XY
// plane of motion moves the ball along the bar once per turn; the centre offset (Δx, Δy) of the ΔL profile plotted
// over the ball's azimuth gives the tilts:
//   E_B0C = Δx/(R·u_z),  E_A0C = −Δy/(R·u_z)    (eq. (4)–(5) with the bar pointing up, u_z = +1),
// u the bar direction (table ball → spindle ball). The location offsets of the axis move the ball across the bar
// and do not show (first order). For another axis the same holds in its own plane (first, second, along) of
// dbb5_axis_line.hpp.
#include <string>

#include "cnccomp/identification/dbb5_axis_line.hpp"
#include "cnccomp/identification/dbb5_circular.hpp"
#include "cnccomp/identification/dbb5_run.hpp"

namespace cnccomp::identification {

struct Dbb5XycResult {
    std::string run, axis;
    int along = 2, first = 0, second = 1;  ///< machine axes as in Dbb5AxisLine
    double radius = 0;                     ///< R: distance of the table ball from the nominal axis, mm
    Eigen::Vector2d centre = Eigen::Vector2d::Zero();  ///< (Δ_first, Δ_second) of the profile over the azimuth, mm
    Vec3 rotation = Vec3::Zero();  ///< tilt of the axis relative to the plane of motion, ISO right-hand (along: 0), rad
    Dbb5PaperTilt paper;           ///< eq. (4)–(5) literally: β = Δx/R, α = −Δy/R (the paper's C axis, bar up)
    CircularTestResult iso;        ///< ISO 230-4 figures of the profile over the azimuth (plotted at radius R)
};

/// True for a rotary run whose bar is along its turning axis and whose ball is off the axis by more than 1 mm.
bool isDbb5XycTest(const MachineModel& m, const measurement::Dbb5Run& run);

/// Throws ModelError for a run that is not an XYC test (see isDbb5XycTest) or a trace that does not match it.
Dbb5XycResult evaluateDbb5XycTest(const MachineModel& m, const measurement::Dbb5Run& run, const BallbarTrace& trace);

}  // namespace cnccomp::identification
