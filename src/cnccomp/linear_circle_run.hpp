#pragma once
// A ball-bar circle of two linear axes as a run of a measurement plan (<circle>, io/plan_xml.hpp): the
// ISO 230-4:2005 circular test in XY, YZ or ZX on any machine, 3-axis included, and its simulation on a machine with
// deviations. The circle is given in axis commands (the description's frame: the controller's machine coordinates
// unless the machine sets machine-zero): the commanded linear axes describe
//     u = c_u + R cos θ,  v = c_v + R sin θ,  the third linear axis at its centre value, rotary axes held,
// with (u, v) the plane's axes as in linear_circle_model.hpp (XY → X, Y; YZ → Y, Z; ZX → Z, X), θ from +u towards +v.
// A CCW pass runs θ upwards (G3 in G17 / G18 / G19 for the commanded axes), CW downwards. The centre (pivot) ball is
// set where the tool ball stands at the centre commands (ISO 230-4 set-up: the pivot at the circle's centre); ΔL =
// |P(θ) − P(centre)| − R, both in the workpiece frame (a table-moving axis carries the pivot with it).
// The data arc runs from `start` to `start + arc` (deg); 360° in XY, the 220° arcs of ISO 230-4 / Renishaw in the
// vertical planes (start −20°: the bar never points down into the table); the instrument records a feed-in and a
// feed-out arc of `overshoot` degrees outside it, which the import drops.
#include <array>
#include <string>
#include <utility>
#include <vector>

#include "cnccomp/circular_test.hpp"
#include "cnccomp/kinematics.hpp"
#include "cnccomp/linear_circle_model.hpp"
#include "cnccomp/run_capture.hpp"

namespace cnccomp {

struct LinearCircleRun {
    std::string name;
    LinearPlane plane = LinearPlane::XY;
    Vec3 centre = Vec3::Zero();     ///< commands of X, Y, Z at the circle centre, mm
    double radius = 100;            ///< circle radius = ball-bar length, mm
    double startDeg = 0;            ///< start of the data arc (θ)
    double arcDeg = 360;            ///< data arc, deg, in (0, 360]
    double stepDeg = 1;             ///< angular spacing of the samples (simulation; the import's sample count check)
    double toolLength = 0;          ///< tool ball along the tool direction from the last tool frame, mm
    /// Where the pivot ball was set relative to the tool ball at the centre commands, workpiece frame, mm: a set-up
    /// error ([MultiTasking]'s work-ball offset for this run). `simulate` puts the pivot there; `identify` estimates its
    /// in-plane part per pass as the centring offset (it is not an input of the identification).
    Vec3 pivotOffset = Vec3::Zero();
    std::vector<std::pair<std::string, double>> hold;  ///< rotary axes held (deg); others at 0
    std::array<double, 2> cyclicPitch{};  ///< screw / scale pitch of u, v (mm) for the cyclic error; 0 = not estimated
    std::string date, instrument, operatorName;  ///< test conditions as the plan states them (may be empty)
    /// feed (mm/min, default 1000), overshoot (deg), directions (default CW then CCW), the instrument's file layout.
    RunCapture capture;
    int line = 0;                   ///< line of the element in the plan (0 when not read from a file)

    /// Throws ModelError for impossible values (R ≤ 0, arc outside (0, 360], step ≤ 0 or coarser than arc / 8,
    /// feed ≤ 0, a direction other than ±1 or repeated, non-finite numbers).
    void validate() const;
    double endDeg() const { return startDeg + arcDeg; }
    /// The pass directions (capture.passes; CW then CCW when empty, the order of the test programs).
    std::vector<int> directions() const;
    /// Sample angles of the data arc from start to end (both ends included, also for a whole turn).
    std::vector<double> dataAnglesDeg() const;
    /// The nominal circle of the model (plane, centre (u, v) of the commands, radius).
    LinearCircle circle() const;
};

/// Commands at θ (deg): rotary axes held, the linear axes on the circle. ModelError naming the run when the machine
/// lacks one of X, Y, Z or a held axis (or a held axis is not rotary).
AxisVector linearCircleCommands(const MachineModel& m, const LinearCircleRun& run, double thetaDeg);
/// Commands at the circle centre (the setup pose: the pivot ball is set under the tool ball here).
AxisVector linearCircleCentreCommands(const MachineModel& m, const LinearCircleRun& run);

/// Simulates what the instrument records on machine `k`: one pass per direction, each over the data arc extended by
/// the overshoot at both ends, every stepDeg (both ends included). ModelError when a command leaves an axis' travel.
std::vector<DirectedTrace> simulateLinearCircle(const Kinematics& k, const LinearCircleRun& run);

}  // namespace cnccomp
