#pragma once
// Which identification method a measurement plan fits, chosen by the kinds of its runs (one `identify` for every
// plan). Each method has the least-squares solution on the exact model (the default, the most accurate) and the
// formulas of the paper the measurement comes from (labelled as such, e.g. for comparison with printed results).
#include <string>
#include <utility>

#include "cnccomp/io/plan_xml.hpp"

namespace cnccomp::identification {

enum class PlanMethod {
    Ballbar,        ///< ball-bar circles around B and C (<run>): every deviation the runs see; formulas: eccentricities
    HeadPatterns,   ///< absolute ball bar about a tilting head at two tool lengths (<absolute-run>): head errors over angle
    RtestLocation,  ///< R-test, one ball (<rtest>): location errors of the rotary axes and squareness of the slides
    RtestTables,    ///< R-test, ≥ 3 balls per swept axis (<rtest>): six errors of each rotary axis over angle
    Dbb5,           ///< DBB5 circles (<dbb5>): location errors of the rotary axes and squareness, ISO 230-4 figures
    Mixed,          ///< runs of several kinds: least squares only
    LinearCircle,   ///< ball-bar circles of the linear axes (<circle>, ISO 230-4): their diagnostics, any machine
    Sphere,         ///< touch probe on a calibration sphere (<sphere>): location errors of the rotary axes
};

/// Short name used on the command line and in messages ("ball-bar", "head-patterns", "rtest-location", …).
const char* planMethodName(PlanMethod m);
/// What the method measures, one line.
const char* planMethodMeasures(PlanMethod m);
/// The formulas the method's `formulas` variant applies, with the paper they come from.
const char* planMethodFormulas(PlanMethod m);

/// The method the plan's runs fit. R-test plans: RtestTables when some rotary axis is swept alone (the others held)
/// with the ball at three or more places, else RtestLocation. Throws ModelError for an empty plan.
PlanMethod classifyPlan(const measurement::MeasurementPlan& plan);

/// Parses a method name (as planMethodName) given on the command line to override the classification; checks that
/// the plan has the runs it needs and says which method the plan fits when it does not. Throws ModelError.
PlanMethod choosePlanMethod(const measurement::MeasurementPlan& plan, const std::string& name);

/// The two rotary axes of the workpiece side in chain order (outer = tilting, inner = table), e.g. ("A", "C");
/// empty strings when the machine has fewer.
std::pair<std::string, std::string> tableRotaryAxes(const MachineModel& machine);

}  // namespace cnccomp::identification
