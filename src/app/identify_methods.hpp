#pragma once
// The identification methods behind `cnccomp identify`, one per kind of plan (identification/plan_method.hpp):
// each runs either the least-squares solution on the exact model or the paper's formulas, prints what it found and
// returns the deviation set (and the report of a least-squares solution). Nothing is written here: the command writes
// every output after every computation succeeded.
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "cnccomp/deviations.hpp"
#include "cnccomp/identification/lsq.hpp"
#include "cnccomp/identification/measured_observations.hpp"
#include "cnccomp/identification/plan_method.hpp"
#include "cnccomp/identification/report.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "cnccomp/linear_circle_identify.hpp"

namespace cnccomp::cli {

struct IdentifyRequest {
    const MachineModel* machine = nullptr;
    const MeasurementPlan* plan = nullptr;  ///< null only for ball-bar formulas from an eccentricity table
    PlanMethod kind = PlanMethod::Ballbar;
    bool formulas = false;                  ///< the paper's formulas instead of least squares
    std::string traces, eccentricities;
    int refine = -1;                        ///< formulas: refinement passes (-1 = the method's default)
    std::string params;                     ///< least squares: deviations to identify ("" = the method's default)
    std::string observe = "traces", solver = "lm", bounds, start;
    int monteCarlo = 0, maxIterations = 50;
    unsigned long seed = 1;
    double rankTolerance = 1e-7;
    std::string outer, inner;               ///< rotary axes of a cradle ("" = the machine's workpiece-side pair)
    std::string volumetricRun;              ///< R-test location: run to compare measured and modelled displacements
    bool components = false;                ///< DBB5: also the component errors of the table axis from its on-axis runs
    bool oneStage = false;                  ///< least squares: one fit of every run (no stage for the linear-axis runs)
    std::string probeLog = "cnccomp-probe.txt";  ///< sphere plans: the probe result file in the traces folder
};

/// One extra output file (angles table, ISO 230-4 table, volumetric comparison, profiles), staged by the command.
struct ExtraOutput {
    std::string option;  ///< the option that names it, e.g. "--angles-out"
    std::function<void(std::ostream&)> write;
};

struct IdentifyOutcome {
    DeviationSet deviations;
    std::optional<IdentificationReport> report;  ///< least-squares solutions
    std::vector<ExtraOutput> extras;
    std::string summary;                         ///< one line: what was identified, how
    /// Least squares on measured ball-bar traces: the imported runs and the engine's result (for the ISO 230-4 table
    /// and the HTML report's polar plots).
    std::optional<MeasuredRuns> measured;
    std::optional<IdentificationResult> result;
    /// Circles of the linear axes (<circle> runs): their diagnostics and ISO 230-4 figures (the reports take them).
    std::optional<LinearCircleIdentification> circles{};
};

/// Runs the method of `r.kind`. Throws ModelError / InputError naming what does not fit.
IdentifyOutcome runIdentification(const IdentifyRequest& r);

/// Prints a least-squares report (values under ISO names, intervals, combinations, residuals per run).
void printReport(const IdentificationReport& report);

}  // namespace cnccomp::cli
