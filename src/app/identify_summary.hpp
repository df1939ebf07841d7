#pragma once
// What an identification found (the façade's result, src/app/identify.hpp), with its reports as text: the brief
// report (one line: what was identified, how) and the full report (the method's tables, the brief line, the
// least-squares report or the circles' diagnostics), as Ceres' Solver::Summary gives BriefReport() and FullReport()
// (ceres-solver, include/ceres/solver.h). Nothing is printed or written here: identify_outputs.hpp stages and
// commits the files, `cnccomp identify` prints the text.
#include <functional>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "cnccomp/deviations.hpp"
#include "cnccomp/identification/lsq.hpp"
#include "cnccomp/identification/measured_observations.hpp"
#include "cnccomp/identification/plan_method.hpp"
#include "cnccomp/identification/report.hpp"
#include "cnccomp/linear_circle_identify.hpp"

namespace cnccomp::app {

/// One extra output file (angles table, ISO 230-4 table, volumetric comparison, profiles), staged by the caller.
struct ExtraOutput {
    std::string option;  ///< the option that names it, e.g. "--angles-out"
    std::function<void(std::ostream&)> write;
};

struct IdentificationSummary {
    DeviationSet deviations;
    std::optional<identification::IdentificationReport> report;  ///< least-squares solutions
    std::vector<ExtraOutput> extras;
    std::string summary;                         ///< one line: what was identified, how (briefReport())
    /// Least squares on measured ball-bar traces: the imported runs and the engine's result (for the ISO 230-4 table
    /// and the HTML report's polar plots).
    std::optional<identification::MeasuredRuns> measured;
    std::optional<identification::IdentificationResult> result;
    /// Circles of the linear axes (<circle> runs): their diagnostics and ISO 230-4 figures (the reports take them).
    std::optional<LinearCircleIdentification> circles{};
    /// The tables the method produced as it worked (ISO 230-4 figures of DBB5 runs, the fits of the formulas, the
    /// errors over angle of a head or a table, the sphere fits), in order; "" when none.
    std::string methodTables{};
    std::string method{};                        ///< the registered method that ran (identify_registry.hpp)
    identification::PlanMethod kind = identification::PlanMethod::Ballbar;       ///< the kind of plan it served
    bool formulas = false;                       ///< the paper's formulas, not least squares

    /// One line: what was identified, how.
    const std::string& briefReport() const { return summary; }
    /// The least-squares report (formatReport) or the circles' diagnostics (formatLinearCircles); "" for formulas.
    std::string resultReport() const;
    /// methodTables, the brief line and resultReport().
    std::string fullReport() const;
};

/// A least-squares report: values under ISO names, intervals, combinations, residuals per run, adequacy, warnings.
std::string formatReport(const identification::IdentificationReport& report);

/// The test conditions, the ISO 230-4 figures and the ranked diagnostics of every circle of the linear axes, and the
/// deviations written.
std::string formatLinearCircles(const LinearCircleIdentification& id);

}  // namespace cnccomp::app
