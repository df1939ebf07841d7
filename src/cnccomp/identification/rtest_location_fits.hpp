#pragma once
// R-test location fits: pivot point position and orientation errors (POPPE) of the rotary axes A and
// C and the three squareness errors of the linear axes of a table-table machine from R-test trajectories, by the
// paper's fits (section 2.2), then the volumetric error along an XYZAC trajectory from the 11 errors (section 3.2).
//
// Trajectories (projections into the machine planes, Gander et al. 1994 least squares):
//  - ball path  = commanded nest position + measured displacement (where the ball actually is);
//  - tool path  = commanded nest position − measured displacement (where the nest goes relative to the ball).
// POPPE: YZA run (A turns) → circle of the ball path → the A line (circle centre and plane normal; the paper's
// circle fit in the plane of interpolation and straight lines in the two perpendicular planes, done jointly as one
// plane fit, which equals the two line fits on a full turn and stays unbiased on an arc) → EY0A EZ0A EB0A EC0A.
// XYC run at A = 0 → the C line → EX0C EY0C EA0C EB0C (relative to the A cradle).
// Squareness, eq. (2) C = (D45 − D135)/D0 on the tool path:
//  - XY: Gander geometric ellipse of the XYC run at A = 0 → EC0Y = C_XY;
//  - ZX: XYC runs with A tilted to ±φ, Z scaled by 1/sin φ so the nominal projection is the circle of D0 →
//        C_ZX = EB0Z · sin φ, averaged over ±φ;
//  - YZ: the same runs project to ellipses elongated along ±φ (segments for a circle seen edge-on); D45 and D135
//        are their long diameters (parametric fit with the commanded C angle as phase) → C_YZ = −EA0Z · sin 2φ.
//  Signs are those of this library's model: EC0Y turns the X slide about +Z, EB0Z and EA0Z turn the Z slide about
//  +Y and +X (so a positive EA0Z tilts Z towards −Y and the paper's C_YZ reads −EA0Z).
// The formulas are first order and each reading also sees the other errors (e.g. the A-axis tilt about Y and the
// ZX squareness both tilt the ball path of the YZA and tilted runs). `refine` Gauss–Newton steps on the exact model
// (reading_refinement.hpp) find the errors whose simulated trajectories give the same fit readings as the
// measurement — as the paper eliminates known errors with its kinematic model (section 3.1); refine = 0 gives the
// plain formulas.
// Source: M. Morávek, O. Hořejš, P. Bach, "Set of geometric errors evaluation based on R-test measurement",
// MM Science Journal 2019 (DOI 10.17973/MMSJ.2019_03_2018106), [Moravek2019]: section 2.2, eq. (2), section 3.2.
// Names: ISO 230-1 (iso_names.hpp); the fits produce link values, the squareness readings C of eq. (2) are the
// aliases CXY, CZX, CYZ of the sample machine (90° minus the angle between the positive directions).
#include <string>
#include <vector>

#include "cnccomp/deviations.hpp"
#include "cnccomp/identification/rtest_fit.hpp"
#include "cnccomp/identification/rtest_run.hpp"

namespace cnccomp::identification {

struct RtestLocationOptions {
    std::string outerAxis = "A", innerAxis = "C";
    int refine = 4;  ///< Gauss–Newton steps on the formula readings (0 = the plain formulas)
};

struct RtestLocationResult {
    DeviationSet deviations;         ///< the 11 errors, present
    DeviationSet plain;              ///< the plain formulas (each reading taken as its error)
    Circle3Fit outerCircle, innerCircle;  ///< ball-path circles of the YZA and XYC runs (measured data)
    EllipseFit xyEllipse;            ///< tool-path ellipse of the XYC run (measured data)
    double cXY = 0, cYZ = 0, cZX = 0;  ///< eq. (2) values of the measured data (dimensionless)
    double phiDeg = 0;               ///< tilt of the ±φ runs
    int refine = 0;
};

/// Finds the runs by what moves: the inner axis alone with the outer at 0 (XYC), at ±φ (tilted XYC), the outer
/// alone (YZA); runs where both turn are ignored (XYZAC, for volumetricErrorAlongRun). Throws ModelError naming what is
/// missing, or when the machine lacks one of the 11 deviations.
RtestLocationResult rtestLocationFits(const MachineModel& m, const std::vector<measurement::RtestRun>& runs,
                              const std::vector<RtestTrace>& traces, const RtestLocationOptions& options = {});

/// Section 3.2: along a (typically XYZAC) run, the measured displacement ("ErrMTCH"), the displacement the
/// identified deviations predict on the exact model ("ErrCALC") and their difference ("deltaERR").
struct VolumetricAlongRun {
    std::vector<Vec3> measured, predicted;
    double rmsResidual = 0, maxResidual = 0;  ///< of |measured − predicted|, mm
    double rmsMeasured = 0;                   ///< of |measured|, mm
};
VolumetricAlongRun volumetricErrorAlongRun(const MachineModel& m, const DeviationSet& identified, const measurement::RtestRun& run,
                                     const RtestTrace& trace);

}  // namespace cnccomp::identification
