#pragma once
// Measurement plans: <plan machine="..."> with one element per run. Run names are unique across all kinds (each
// run's data is DIR/<name>.csv).
//  <run>          ball-bar run of [MultiTasking] Table 2 (W-side ball set on the T-side ball at the setup commands);
//  <absolute-run> the same attributes, but Ball 2 sits at its nominal position and ΔL is absolute ([FanWuLi]);
//  <rtest>        R-test run ([Moravek2019] / [RotaryTableModel]): ball on the table, nest on the spindle, rotary sweeps;
//  <dbb5>         DBB5 run (ball bar held at 45°): linear circle in a plane, rotary-axis circle, or cone frustum.
//  <circle>       ball-bar circle of two linear axes (ISO 230-4), any machine (linear_circle_run.hpp).
#include <string>

#include "cnccomp/measurement/plan.hpp"

namespace cnccomp::io {

/// Attributes of <run> and <absolute-run>: name (a plain file name: DIR/<name>.csv), test (B-X … B-axial), LB RB RC ZC (mm), start end step (deg),
/// tool-ball-offset / work-ball-offset ("x y z" mm), estimate-mounting (none|tool|work|both: mounting offsets as
/// nuisance parameters; an absolute run takes none|work), head-axis / table-axis (default B / C).
/// Measured runs (RunCapture, cnccomp/run_capture.hpp): <run>/<absolute-run> take feed (mm/min), feed-radius (mm),
/// overshoot (deg) and directions ("ccw", "cw", "ccw cw", "cw ccw"); one optional <instrument> element gives, for every
/// run, angle-column, time-column, length-column, pass-column, length-unit (um|mm|nm|in), angle-unit (deg|rad),
/// time-unit (s|ms), decimal (auto|point|comma), length (absolute|relative), drift (keep|remove); a run may override
/// each of them with the same attribute. <dbb5> and <rtest> runs keep their own layouts.
/// <rtest name ball="x y z" [nest-length=100] [steps=36] [ball-offset="x y z"] [estimate-ball=false]> with children
/// <sweep axis start end/> (deg, linear in the pose index) and <hold axis deg/>.
/// <dbb5 name kind="linear|rotary|cone" LB [tool-length=100] ball="x y z" [start=0 end=360 step=5] (linear:
/// plane="XY|YZ|ZX"; rotary: axis direction="x y z" [setup=0]; cone: [cone-tilt=10 tool-angle=15 bar-angle=45 setup=0],
/// deg) > with children <hold axis deg/>.
/// <circle name plane="XY|YZ|ZX" radius [centre="x y z"=0 start=0 arc=360 step=1 tool-length=0 pivot-offset="x y z"=0 pitch="pu pv"=0
/// feed=1000 overshoot=0 directions="cw ccw" date instrument operator, the instrument attributes]> with children
/// <hold axis deg/> (rotary axes): a ball-bar circle of the linear axes (linear_circle_run.hpp), centre in axis
/// commands, arc in (0, 360]°.
measurement::MeasurementPlan readPlanXml(const std::string& path);
/// Throws InputError naming the plan file and the line of <plan> when the plan names another machine than `machine`.
void checkPlanMachine(const measurement::MeasurementPlan& plan, const std::string& planPath, const std::string& machine);
void writePlanXml(const std::string& path, const measurement::MeasurementPlan& plan);
std::string formatPlanXml(const measurement::MeasurementPlan& plan);

}  // namespace cnccomp::io
