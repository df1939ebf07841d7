#pragma once
// The motion of every run of a measurement plan, as a test program has to make it: where the instrument is set, the
// sweep as a function of its parameter (an angle in degrees, or the pose index of an R-test), and the samples the
// simulation evaluates. One source for `cnccomp testprog` (which writes it) and `cnccomp verify` (which reads the
// written programs back and checks them against it).
//  <run>          [MultiTasking] Table 2 commands (runCommands), W-side ball set at setupCommands (eq. (11)–(13));
//  <absolute-run> the same commands, Ball 2 at its nominal position ([FanWuLi] section 3.1);
//  <dbb5>         dbb5Commands / dbb5SetupCommands ([IbarakiDBB5]);
//  <rtest>        rtestCommands, stop-and-go poses, the ball centred in the nest at the first pose ([Moravek2019] / [RotaryTableModel]);
//  <circle>       linearCircleCommands, the pivot ball set under the tool ball at the centre (ISO 230-4).
#include <functional>
#include <string>
#include <vector>

#include "cnccomp/io/plan_xml.hpp"

namespace cnccomp::postproc::testprog {

enum class RunKind { Ballbar, AbsoluteBallbar, Rtest, Dbb5, LinearCircle };
/// "ball bar", "absolute ball bar", "R-test", "DBB5", "linear circle".
const char* runKindName(RunKind k);

struct RunMotion {
    std::string name;
    RunKind kind = RunKind::Ballbar;
    /// Commands (description frame: mm, rad) at which the instrument is set: the W-side / table ball is set on the
    /// tool-side ball (ball bar, DBB5), Ball 2 is checked at its nominal place (absolute bar), the nest is centred on
    /// the ball (R-test).
    AxisVector setup;
    /// Commands at sweep parameter t (deg; R-test: pose index, linear between poses as a G1 move makes it).
    std::function<AxisVector(double)> at;
    /// Sweep points from start to end: the simulation's samples first (in sweep order), then the closing point of a
    /// whole turn (or the end of a sweep the step does not divide) when it is not a sample.
    std::vector<double> points;
    size_t sampleCount = 0;      ///< the first sampleCount points are the samples the simulation evaluates
    bool continuous = true;      ///< false: stop-and-go poses (R-test), measured at standstill
    double toolLength = 0;       ///< tool-side ball / nest: distance along the tool direction from the last tool frame, mm
    std::string parameter;       ///< what t is, e.g. "B angle (deg)", "pose"
    std::vector<std::string> notes;  ///< setup description (run type and geometry), one line each
    std::string setupAction;     ///< what the operator does at the setup pose
    std::string captureAction;   ///< what the operator does before the data capture starts

    const BallbarRun* ballbar = nullptr;  ///< the plan's run (ball bar, absolute ball bar), else null
    const measurement::Dbb5Run* dbb5 = nullptr;
    const measurement::RtestRun* rtest = nullptr;
    const LinearCircleRun* circle = nullptr;  ///< <circle>: its feed, overshoot and first direction drive the program
};

/// Every run of the plan in plan order: <run>, <absolute-run>, <dbb5>, <rtest>, <circle>. The plan must outlive the result.
/// Throws ModelError for a run the machine cannot make (unknown axes, impossible geometry).
std::vector<RunMotion> planMotions(const MachineModel& machine, const measurement::MeasurementPlan& plan);

/// Shape of a continuous sweep in the controller's coordinates: a circle in a principal plane (XY, ZX or YZ) run
/// at a constant rate with every rotary axis linear in the same parameter, which is exactly what one G2/G3 block with
/// rotary words makes between two sweep points (RS274NGC arc with rotary axes: linear in the arc's angle).
struct PathShape {
    bool circle = false;
    int plane = 17;            ///< 17 (X, Y), 18 (Z, X), 19 (Y, Z): the axes of G17/G18/G19
    int axis0 = -1, axis1 = -1;  ///< machine axes of the plane, in that order
    double c0 = 0, c1 = 0;     ///< centre, controller coordinates (mm)
    double radius = 0;         ///< mm
    double rate = 0;           ///< d(angle)/dt in the plane, rad per unit t; > 0: counter-clockwise seen from +normal
    bool rotaryMoves = false;  ///< some rotary axis turns during the sweep
    bool linearMoves = false;  ///< some linear axis moves during the sweep
};

/// Examines motion.at in the controller's coordinates over [from, to] (any order) every `step` and half-way between.
PathShape analysePath(const MachineModel& machine, const RunMotion& motion, double from, double to, double step);

}  // namespace cnccomp::postproc::testprog
