#pragma once
// DBB5 runs (Ibaraki et al., "Identification of motion error sources on five-axis machine tools by ball-bar
// measurements", 1st report): a double ball bar whose balls are held from 45° to the spindle axis, so that circles in
// the XY, YZ and ZX planes and rotary-axis circles can all be measured from one setup.
//  - linear circle: the rotary axes hold still, the linear axes move the spindle ball on a circle of radius LB
//    around the table ball (ISO 230-4 circular test) in the plane XY, YZ or ZX (angle 0 along the first letter,
//    90° towards the second);
//  - rotary circle: one rotary axis turns (full turn or arc), the table ball turns with it, and the linear axes
//    keep the spindle ball at LB along a fixed bed-frame direction from the table ball ("C-X (−Z)" etc.; with the bar
//    along the turning axis and the ball off it, the ISO 10791-6 XYC test, dbb5_xyc_test.hpp);
//  - cone frustum: both rotary axes of a tilting table and the linear axes move as when a NAS 979 cone frustum is
//    cut; the spindle ball circles the table ball on a cone (dbb5_cone_frustum.hpp).
// The table ball is set where the spindle ball stands at the setup pose (sweep angle `setupDeg`, spindle ball on
// the table ball), as for the [MultiTasking] ball bar; ΔL = L − LB.
// The run as planned (a measurement): its geometry and its sweep angles. The commands a machine runs for it, and its
// simulation, are identification/dbb5_run.hpp.
#include <string>
#include <utility>
#include <vector>

#include "cnccomp/geometry.hpp"

namespace cnccomp::measurement {

struct Dbb5Run {
    enum class Kind { LinearCircle, RotaryCircle, ConeFrustum };
    std::string name;
    Kind kind = Kind::LinearCircle;
    double LB = 100.0;                 ///< bar length, mm
    double toolLength = 100.0;         ///< spindle ball: distance along the tool direction from the last tool frame, mm
    Vec3 ball = Vec3::Zero();          ///< nominal table-ball centre in the workpiece frame, mm
    double startDeg = 0.0, endDeg = 360.0, stepDeg = 5.0;
    double setupDeg = 0.0;             ///< sweep angle of the setup pose (rotary circles)
    std::vector<std::pair<std::string, double>> hold;  ///< rotary axes held at a position (deg); others stay at 0
    std::string plane = "XY";          ///< linear circle: XY, YZ or ZX
    std::string axis = "C";            ///< rotary circle: the turning axis
    Vec3 barDirection = -Vec3::UnitX();  ///< rotary circle: table ball → spindle ball, bed frame (unit)
    /// Cone frustum (sweep angle = azimuth φ about the cone axis, workpiece frame): cone axis tilted about the
    /// workpiece Y, tool axis leaning towards it along the generatrix, bar inclined from it; degrees.
    double coneTiltDeg = 10.0, toolAngleDeg = 15.0, barAngleDeg = 45.0;

    /// Throws ModelError for impossible geometry (non-positive LB, zero step, unknown plane, zero direction …).
    void validate() const;
    /// Sweep angles in degrees; a whole turn does not repeat its first angle (as BallbarRun::anglesDeg()).
    std::vector<double> anglesDeg() const;
    /// Unit vectors (first, second) of a linear circle's plane.
    std::pair<Vec3, Vec3> planeAxes() const;
};

}  // namespace cnccomp::measurement
