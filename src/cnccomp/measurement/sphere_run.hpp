#pragma once
// Touch-probe runs on a calibration sphere: a precision sphere fixed on the table, a touch probe in the
// spindle. At each pose of the rotary axes the probe touches the sphere at a pole (along the tool axis) and at a ring of
// points at one latitude; the touches give the sphere's centre at that pose (measurement/sphere_fit.hpp). The centres
// against the sphere's nominal position observe the tool–table error, as the R-test's displacements do (HEIDENHAIN
// KinematicsOpt cycle 451 and Siemens CYCLE996 measure the same way, for their own kinematics only).
// The run as planned; its commands, simulation and observation are identification/sphere_probe.hpp.
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "cnccomp/geometry.hpp"
#include "cnccomp/measurement/rtest_run.hpp"

namespace cnccomp::measurement {

/// Rotary-axis positions of some poses: the axes in `sweeps` linear in the pose index from start to end over `steps`
/// intervals (a whole turn does not repeat its first pose); `steps` = 0: one pose, every axis held (start == end).
struct SpherePoseGroup {
    std::vector<RotarySweep> sweeps;
    int steps = 0;
    int line = 0;  ///< line of the element in the plan file (0 when not read from a file)
};

/// One pose: the rotary axes' angles (deg) by axis name; axes not named stay at 0.
using SpherePose = std::vector<std::pair<std::string, double>>;

struct SphereRun {
    std::string name;
    int line = 0;                  ///< line of <sphere> in the plan file (0 when not read from a file)
    Vec3 centre = Vec3::Zero();    ///< nominal sphere centre, workpiece (table) frame, mm
    double diameter = 25.0;        ///< sphere diameter, mm
    double stylusDiameter = 6.0;   ///< stylus ball diameter, mm
    double toolLength = 100.0;     ///< stylus ball centre: distance along the tool direction from the last tool frame, mm
    double approach = 5.0;         ///< each touch starts this far outside the surface and may go as far inside, mm
    double feed = 100.0;           ///< probing feed, mm/min
    double clearance = 10.0;       ///< safe distance of every move between touches from the sphere, mm
    double window = std::numeric_limits<double>::quiet_NaN();  ///< a touch farther than this from the nominal
                                   ///< surface is refused (mm); NaN = half the approach distance
    double latitudeDeg = 20.0;     ///< latitude of the ring touches above the sphere's equator (0 .. 60°), towards the probe
    int ringTouches = 4;           ///< touches on the ring (≥ 4), evenly spaced, the first along the tool frame's +X
    double triggerOffset = 0.0;    ///< stated trigger offset (pre-travel) of the probe, mm: the fit's radius is
                                   ///< diameter/2 + stylusDiameter/2 − triggerOffset
    bool estimateTrigger = true;   ///< identification: the trigger offset is a nuisance parameter shared by every pose
    std::vector<SpherePoseGroup> groups;  ///< the poses, in order
    // Simulation only (what the real set-up differs by):
    Vec3 sphereOffset = Vec3::Zero();  ///< actual minus nominal sphere centre (mounting error), mm
    double triggerError = 0.0;     ///< actual minus stated trigger offset, mm

    /// Throws ModelError naming the run for non-finite or out-of-range geometry, an axis given twice in a group, a
    /// group whose sweep does not move, or no pose.
    void validate() const;
    /// Every pose, in plan order.
    std::vector<SpherePose> poses() const;
    /// Touches per pose: the pole and the ring.
    int touchesPerPose() const { return 1 + ringTouches; }
    /// Radius of the sphere the stylus ball centre touches, as the fit takes it (stated trigger offset), mm.
    double fitRadius() const { return 0.5 * (diameter + stylusDiameter) - triggerOffset; }
    /// The acceptance window, mm (window, or half the approach distance).
    double touchWindow() const { return window == window ? window : 0.5 * approach; }
};

}  // namespace cnccomp::measurement
