#pragma once
// The files of an identification and the text that says what was written: what `cnccomp identify` asks for with
// --out, --merge, --report (R.json or R.html with --report-controllers / --report-grid / --report-plane), --angles-out,
// --volumetric-out, --iso-out and --profile-out, made from the façade's summary (identify.hpp, identify_summary.hpp).
// The façade computes and writes nothing; this unit writes, all or nothing: every file is staged and committed
// together (io/output_set.hpp), so a request that fails late (an extra output the method does not write, a folder
// that does not exist, a map grid the report cannot draw) leaves every target as it was.
//
//   checkOutputRequests(outputs, options);                      // before any measured file is read
//   const IdentificationSummary s = identify(machine, plan, options);
//   const WrittenIdentification w = writeIdentificationOutputs(machine, plan, options, s, outputs);
//   text = writtenIdentificationText(s, outputs, w, plan);
#include <string>
#include <vector>

#include "app/identify_options.hpp"
#include "app/identify_summary.hpp"
#include "app/report/report_data.hpp"
#include "cnccomp/machine.hpp"
#include "cnccomp/measurement/plan.hpp"

namespace cnccomp::app {

/// Where the identification's files go ("" = not written), and the files it read (never overwritten).
struct IdentificationOutputs {
    std::string deviations;         ///< --out: the deviation CSV (ISO names and values, paper aliases); required
    std::string merge;              ///< --merge: a deviation CSV the identified deviations replace theirs in ("" = none)
    std::string report;             ///< --report: R.html (page, SVGs, R.summary.json) or a JSON report
    std::string anglesOut;          ///< --angles-out: head patterns, the head's errors at every measured angle
    std::string volumetricOut;      ///< --volumetric-out: R-test location, measured vs modelled displacement
    std::string isoOut;             ///< --iso-out: DBB5, ISO 230-4 figures of every run
    std::string profileOut;         ///< --profile-out: DBB5 --components, the component profiles over angle
    std::string reportControllers;  ///< HTML report: controllers (comma list) whose coverage and residual to show
    std::string reportGrid;         ///< HTML report: map grid as for `cnccomp map` ("" = the default grid)
    std::string reportPlane = "XY"; ///< HTML report: map plane as for `cnccomp map --plane`
    std::string machineFile;        ///< the machine XML read (an input; named in the HTML report)
    std::string planFile;           ///< the plan XML read ("" = none; an input; named in the HTML report)
    std::vector<std::string> otherInputs;  ///< further files read, e.g. --truth: never overwritten
};

/// What the caller prints once the files are written.
struct WrittenIdentification {
    /// --merge: one line per reversal axis saying whose value was kept (reversalMergeLines, laser_deviation.hpp).
    std::vector<std::string> mergeLines;
    /// Least squares on measured ball-bar traces: the ISO 230-4 figures of every run as measured and with the
    /// identified deviations compensated (report::measuredRunSections); empty otherwise.
    std::vector<report::RunSection> runs;
};

/// The files an identification reads, in the order their refusals name them: machine, plan, otherInputs,
/// options.start, options.eccentricities, merge ("" entries kept; they match nothing).
std::vector<std::string> identificationInputs(const IdentificationOutputs& outputs, const IdentificationOptions& options);

/// Checks the requests that need no measurement, in this order (ModelError / InputError, the messages of
/// `cnccomp identify`): --report-controllers and --report-grid only with an HTML report; --profile-out only with
/// --components; no output naming an input (identificationInputs) and no two outputs naming the same file;
/// --volumetric-out only with --volumetric RUN. `cnccomp identify` calls it before it reads a measurement;
/// writeIdentificationOutputs calls it again.
void checkOutputRequests(const IdentificationOutputs& outputs, const IdentificationOptions& options);

/// Checks the requests against what the identification found (a --report the method writes none of, an extra output
/// it does not write, a map or controller section the circles of the linear axes have none of), then stages every
/// output (the deviation CSV, or with --merge the base read and merged, mergeDeviations; the report; the extras) and
/// commits them together. Throws before anything is written; a failure while staging leaves every target as it was.
/// `plan` may be null as for identify().
WrittenIdentification writeIdentificationOutputs(const MachineModel& machine, const measurement::MeasurementPlan* plan,
                                                 const IdentificationOptions& options,
                                                 const IdentificationSummary& summary,
                                                 const IdentificationOutputs& outputs);

/// The text `cnccomp identify` prints once the files are written: the adequacy warning (a model that does not fit
/// says so first), the brief line with where the deviations and the report went, the merge lines, the summary's
/// resultReport(), the ISO 230-4 table of the ball-bar runs, and per measured time-sampled run the feed the data give
/// and the binning of dense files.
std::string writtenIdentificationText(const IdentificationSummary& summary, const IdentificationOutputs& outputs,
                                      const WrittenIdentification& written, const measurement::MeasurementPlan* plan);

}  // namespace cnccomp::app
