#pragma once
// The values a controller's files carry, fitted to what that controller can hold: the least-squares
// best of the controller's adjustable values against the identified machine's tool-tip error over a stated workspace,
// with "no compensation" and "the identified values copied" always among the candidates, so that the files never
// leave more error than none on that workspace.
#include <optional>
#include <string>
#include <vector>

#include "cnccomp/deviations.hpp"
#include "controllers/backend.hpp"

namespace cnccomp::controllers::common {

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
    std::optional<DeviationSet> fittedValues{};  ///< the fitted candidate's values (written or not)
    int heldValues = -1;         ///< entries of the deviation vector the files respond to (-1: not searched, the copy held all)
};

/// When one figure "leaves more" than another: by more than 1 % of it or 0.01 um, whichever is larger (below that the
/// difference is the files' rounding and the solvers' tolerance, e.g. 0.001 vs 0.001 um).
struct FitTolerance {
    double relative = 0.01;
    double absolute = 0.01e-3;  ///< mm
};
inline constexpr FitTolerance kFitTolerance{};
/// The copy of the identified values leaving at most this fraction of none's largest tip error: the controller holds
/// every deviation, and the fit is the copy (exactly).
inline constexpr double kHoldsAllFraction = 0.02;

/// Whether `a` leaves more tool-tip error than `b` (largest or RMS) beyond kFitTolerance.
bool leavesMore(const FitFigures& a, const FitFigures& b);

/// The poses the candidates are judged on (and the fit looks at besides its subset of the workspace): the workspace and
/// each axis alone swept through its travel, the others at 0 (fit.cpp explains why: a grid of a few samples per axis
/// misses what a table-basis fit does between them).
FitWorkspace judgedWorkspace(const MachineModel& m, const FitWorkspace& workspace);

/// Tool-tip error of the identified machine over judgedWorkspace(workspace) with `b`'s files for `written` loaded.
FitFigures fitFigures(const Backend& b, const MachineModel& m, const DeviationSet& identified, const DeviationSet& written,
                      const FitWorkspace& workspace);

/// Fits the values `b` writes: every entry of the deviation vector the backend's files respond to is a free value, the
/// others are zero; least squares on the tool-tip error of `identified` over `workspace` (every pose at every tool
/// length) through b.emit() and b.apply(). Candidates (their figures over judgedWorkspace(workspace), on the files
/// emitted and read back): none (all zero), the identified values copied, the fit; the
/// written one has the smallest RMS among those whose largest error is not above none's. When the copy leaves at most
/// kHoldsAllFraction of none's largest error the controller holds everything and the copy is the fit (written ==
/// identified exactly).
FitOutcome fitControllerValues(const Backend& b, const MachineModel& m, const DeviationSet& identified,
                               const FitWorkspace& workspace);

}  // namespace cnccomp::controllers::common
