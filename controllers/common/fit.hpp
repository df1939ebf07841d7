#pragma once
// The values a controller's files carry, fitted to what that controller can hold (issue 17 part 1): the least-squares
// best of the controller's adjustable values against the identified machine's tool-tip error over a stated workspace,
// with "no compensation" and "the identified values copied" always among the candidates, so that the files never
// leave more error than none on that workspace.
#include <string>
#include <vector>

#include "cnccomp/deviations.hpp"
#include "controllers/backend.hpp"

namespace cnccomp::controllers {

/// Where the fit looks: programmed commands of the nominal machine (the controller's program words read as the
/// nominal machine's commands) at each of a set of tool lengths.
struct FitWorkspace {
    std::vector<AxisVector> poses;
    std::vector<double> toolLengths;  ///< mm
    std::string description;          ///< for the files and the output, e.g. "plan P.xml (6 runs) + 5 per axis over the travel, tools 0 100 360 mm"
};

/// Tool-tip error of the identified machine over the workspace with one candidate's files loaded.
struct FitFigures {
    double maxTip = 0, rmsTip = 0;  ///< mm
    double maxAxis = 0;             ///< rad, tool-axis error
};

struct FitOutcome {
    DeviationSet written;        ///< the values to emit (what the backend's emit() gets)
    std::string chosen;          ///< "fitted", "identified", "none"
    FitFigures none, copied, fitted;
    std::vector<std::string> notes;  ///< header lines: the workspace, the candidates' figures, the choice
};

/// Fits the values `b` writes: every deviation the backend's files respond to is a free value, the others are zero;
/// least squares on the tool-tip error of `identified` over `workspace` through b.emit() and b.apply().
FitOutcome fitControllerValues(const Backend& b, const MachineModel& m, const DeviationSet& identified,
                               const FitWorkspace& workspace);

}  // namespace cnccomp::controllers
