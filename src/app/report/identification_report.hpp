#pragma once
// The report of `cnccomp identify`: ReportData (report_data.hpp) filled from the measured runs and the
// identification result. "After" everywhere means: the identified deviations compensated.
//  - per ball-bar run: the passes as measured, and after = measured − (ΔL predicted with the identified deviations −
//    ΔL predicted on the nominal machine), both with the run's mounting offsets; for a relative instrument both less
//    the estimated length offset dL0; ISO 230-4 figures of both;
//  - the deviations with 95 % intervals, the unidentified ones and the identifiable combinations;
//  - a volumetric map of the identified machine, and per requested controller its coverage, the tool-tip error left
//    when that controller compensates the identified deviations (its apply model, over workspace samples) and the
//    map after it, all maps on one colour scale.
#include <string>
#include <vector>

#include "cnccomp/identification/lsq.hpp"
#include "cnccomp/identification/measured_observations.hpp"
#include "app/report/compensation_map.hpp"
#include "app/report/report_data.hpp"

namespace cnccomp::app::report {

/// Ball-bar runs of a measured plan: before / after traces per pass, ISO 230-4 figures, fit RMS.
/// `measured.observations` must be those the identification used (plan.runs first).
std::vector<RunSection> measuredRunSections(const MachineModel& machine, const measurement::MeasurementPlan& plan,
                                            const identification::MeasuredRuns& measured, const identification::IdentificationResult& result);

/// The deviations of a report: every requested one, identified or not (display units um / arcsec).
std::vector<DeviationRow> deviationRows(const identification::IdentificationReport& report);

/// Map of the identified machine ("before") and, per controller backend name, the coverage and the residual of that
/// controller compensating the identified deviations (figures over workspaceSamples(machine, 5) less the poses whose
/// tool axis is parallel to a rotary axis) with its "after" map.
void addCompensationSections(ReportData& data, const MachineModel& machine, const DeviationSet& identified,
                             const std::vector<std::string>& controllers, const MapOptions& options);

}  // namespace cnccomp::app::report
