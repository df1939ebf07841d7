#include "app/identify_outputs.hpp"

#include <algorithm>
#include <cmath>
#include <string_view>
#include <utility>

#include <fmt/format.h>

#include "app/report/html_report.hpp"
#include "app/report/identification_report.hpp"
#include "app/report/linear_circle_report.hpp"
#include "app/text_out.hpp"
#include "cnccomp/error.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/linear_circle_json.hpp"
#include "cnccomp/io/output_set.hpp"
#include "cnccomp/io/report_json.hpp"
#include "cnccomp/io/text_util.hpp"
#include "cnccomp/laser_deviation.hpp"

namespace cnccomp::app {
using namespace cnccomp::identification;
using namespace cnccomp::io;
using namespace cnccomp::measurement;

namespace {

/// The output options with their paths, in the order they are checked ("" = not asked for).
std::vector<std::pair<std::string, std::string>> outputPaths(const IdentificationOutputs& o) {
    return {{"--out", o.deviations},     {"--report", o.report},          {"--angles-out", o.anglesOut},
            {"--volumetric-out", o.volumetricOut}, {"--iso-out", o.isoOut}, {"--profile-out", o.profileOut}};
}

bool htmlReport(const IdentificationOutputs& o) { return !o.report.empty() && report::isHtmlPath(o.report); }

/// The extra outputs asked for, each with the summary's writer; ModelError for one the method does not write.
std::vector<std::pair<std::string, const ExtraOutput*>> requestedExtras(const IdentificationSummary& res,
                                                                         const IdentificationOutputs& o) {
    std::vector<std::pair<std::string, const ExtraOutput*>> extras;
    for (const auto& [option, path] : outputPaths(o)) {
        if (path.empty() || option == "--out" || option == "--report") continue;
        const auto it = std::find_if(res.extras.begin(), res.extras.end(),
                                     [&](const ExtraOutput& e) { return e.option == option; });
        if (it == res.extras.end())
            throw ModelError(fmt::format("{} does not apply to the {} method", option, planMethodName(res.kind)));
        extras.emplace_back(path, &*it);
    }
    return extras;
}

/// The HTML report of a least-squares identification: facts, alarms and warnings of the solver report, the ball-bar
/// runs before / after, the deviations and combinations, the maps and the requested controllers' sections.
report::ReportData leastSquaresReportData(const MachineModel& m, const MeasurementPlan* plan,
                                          const IdentificationOptions& r, const IdentificationSummary& res,
                                          const IdentificationOutputs& o, const std::vector<report::RunSection>& runs) {
    const IdentificationReport& rep = *res.report;
    report::ReportData d;
    d.title = fmt::format("Identification of {}", m.name);
    d.machine = m.name;
    d.facts = {{"machine file", o.machineFile}, {"plan", o.planFile}, {"traces", r.traces}, {"deviations written", o.deviations},
               {"solver", fmt::format("{}: {} after {} iteration(s)", rep.solver, rep.termination, rep.iterations)},
               {"fit", fmt::format("{} samples, rank {}/{}, condition number {:.4g}, sigma {:.4f} µm", rep.observations,
                                   rep.rank, rep.unknowns, rep.conditionNumber, rep.sigma / kUm)}};
    if (!rep.stages.empty()) d.facts.push_back({"fitted in two stages", rep.stages});
    if (!rep.adequacy.fits) d.alarms.push_back("WARNING: " + rep.adequacy.message);
    for (const std::string& w : rep.warnings)
        if (rep.adequacy.fits || w != rep.adequacy.message) d.warnings.push_back(w);
    d.afterNote = "the run with the identified deviations compensated";
    d.runs = runs;
    d.deviations = report::deviationRows(rep);
    for (const Combination& c : rep.identifiable) d.combinations.push_back(c.text);
    report::MapOptions mo;
    mo.grid = o.reportGrid;
    mo.plane = o.reportPlane;
    mo.toolLength = plan && !plan->runs.empty() ? plan->runs.front().RB : 0.0;
    report::addCompensationSections(d, m, res.deviations, commaItems(o.reportControllers), mo);
    return d;
}

/// Stages --report: the circles' HTML page or JSON, or the least-squares HTML page or solver JSON report.
void stageReport(OutputSet& staged, const MachineModel& m, const MeasurementPlan* plan, const IdentificationOptions& r,
                 const IdentificationSummary& res, const IdentificationOutputs& o,
                 const std::vector<report::RunSection>& runs) {
    const bool html = htmlReport(o);
    if (res.circles && html) {
        if (!o.reportControllers.empty() || !o.reportGrid.empty())
            throw ModelError("--report-controllers and --report-grid: the circles of the linear axes write no maps or "
                             "controller sections yet");
        report::stageHtmlReport(staged, o.report,
                                report::linearCircleReportData(m.name, *res.circles,
                                                               {{"machine file", o.machineFile}, {"plan", o.planFile},
                                                                {"traces", r.traces}, {"deviations written", o.deviations},
                                                                {"identification", res.summary}}));
    } else if (res.circles && !o.report.empty()) {
        staged.add(o.report, formatLinearCircleJson(m.name, *res.circles));
    } else if (html) {
        report::stageHtmlReport(staged, o.report, leastSquaresReportData(m, plan, r, res, o, runs));
    } else if (!o.report.empty()) {
        staged.add(o.report, formatReportJson(*res.report));
    }
}

/// ISO 230-4 figures of every ball-bar run, as measured and with the identified deviations compensated.
void circularTestTable(const TextOut& out, const std::vector<report::RunSection>& runs) {
    if (runs.empty()) return;
    out("ISO 230-4 circular test figures (um; after = identified deviations compensated):\n");
    out("{:<18} {:<7} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9} {:>12} {:>9} {:>9}\n", "run", "passes", "G before", "G after",
        "Fmax bef", "Fmin bef", "Fmax aft", "Fmin aft", "mean R mm", "H before", "H after");
    const auto um = [](double v) { return std::isfinite(v) ? fmt::format("{:9.3f}", v / kUm) : fmt::format("{:>9}", "-"); };
    for (const report::RunSection& r : runs) {
        std::string passes;
        for (const report::PolarPass& p : r.passes) passes += p.direction > 0 ? "+" : "-";
        out("{:<18} {:<7} {} {} {} {} {} {} {:12.5f} {} {}\n", r.name, passes, um(r.before.G), um(r.after.G),
            um(r.before.Fmax), um(r.before.Fmin), um(r.after.Fmax), um(r.after.Fmin), r.before.meanRadius, um(r.before.H),
            um(r.after.H));
    }
}

/// Per measured ball-bar run: the feed its time-sampled data give, and how a dense file was binned.
void importLines(const TextOut& out, const IdentificationSummary& res, const MeasurementPlan* plan) {
    if (!res.measured || !plan) return;
    for (size_t i = 0; i < res.measured->ballbar.size(); ++i) {
        const TraceImportSummary& s = res.measured->ballbar[i].summary;
        const BallbarRun& run = plan->runs[i];
        if (s.feedEstimate > 0)
            out("feed from the data, run {}: {:.1f} mm/min (plan {:g}, {:+.2f} %, allowed ±{:.2f} %)\n", run.name,
                s.feedEstimate, run.capture.feed, 100 * (s.feedEstimate / run.capture.feed - 1), 100 * s.feedTolerance);
        if (s.binnedFrom > 0)
            out("run {}: {} samples averaged into {} bins of the plan's {:g}° step\n", run.name, s.binnedFrom,
                s.binnedInto, std::abs(run.stepDeg));
    }
}

}  // namespace

std::vector<std::string> identificationInputs(const IdentificationOutputs& o, const IdentificationOptions& options) {
    std::vector<std::string> inputs{o.machineFile, o.planFile};
    inputs.insert(inputs.end(), o.otherInputs.begin(), o.otherInputs.end());
    inputs.insert(inputs.end(), {options.start, options.eccentricities, o.merge});
    return inputs;
}

void checkOutputRequests(const IdentificationOutputs& o, const IdentificationOptions& options) {
    if ((!o.reportControllers.empty() || !o.reportGrid.empty()) && !htmlReport(o))
        throw ModelError("--report-controllers and --report-grid belong to an HTML report: give --report R.html");
    if (!o.profileOut.empty() && !options.components) throw ModelError("--profile-out needs --components");
    // Outputs: never an input, never twice.
    const std::vector<std::string> inputs = identificationInputs(o, options);
    const std::vector<std::pair<std::string, std::string>> outputs = outputPaths(o);
    for (size_t i = 0; i < outputs.size(); ++i) {
        if (outputs[i].second.empty()) continue;
        refuseToOverwrite(outputs[i].second, inputs);
        for (size_t j = 0; j < i; ++j)
            if (outputs[j].second == outputs[i].second)
                throw ModelError(fmt::format("{} and {} name the same file '{}'", outputs[j].first, outputs[i].first,
                                             outputs[i].second));
    }
    if (!o.volumetricOut.empty() && options.volumetricRun.empty())
        throw ModelError("--volumetric-out needs --volumetric RUN");
}

WrittenIdentification writeIdentificationOutputs(const MachineModel& m, const MeasurementPlan* plan,
                                                 const IdentificationOptions& r, const IdentificationSummary& res,
                                                 const IdentificationOutputs& o) {
    checkOutputRequests(o, r);
    if (!o.report.empty() && !res.report && !res.circles)
        throw ModelError(fmt::format("--report: the {} of '{}' writes no least-squares report",
                                     res.formulas ? "formulas" : "method", planMethodName(res.kind)));
    const std::vector<std::pair<std::string, const ExtraOutput*>> extras = requestedExtras(res, o);
    WrittenIdentification w;
    // Ball-bar runs of a least-squares solution on measured traces: ISO 230-4 figures before / after.
    if (res.measured && res.result && plan) w.runs = report::measuredRunSections(m, *plan, *res.measured, *res.result);

    // Everything is computed: stage every output, then commit them together (all or nothing).
    OutputSet staged(identificationInputs(o, r));
    // --merge: the identified deviations replace theirs in an existing set (e.g. the laser's positioning components
    // and a rotary-axis identification), the others are kept (laser_deviation.hpp, mergeDeviations).
    // A reversal value this run did not determine keeps the base's (said in the text, reversalMergeLines).
    if (o.merge.empty()) {
        staged.add(o.deviations, formatDeviationCsv(res.deviations));
    } else {
        const DeviationSet base = readDeviationCsv(o.merge, m);
        w.mergeLines = reversalMergeLines(base, res.deviations, "this identification");
        staged.add(o.deviations, formatDeviationCsv(mergeDeviations(base, res.deviations)));
    }
    stageReport(staged, m, plan, r, res, o, w.runs);
    for (const auto& [path, e] : extras) staged.add(path, e->write);
    staged.commit();
    return w;
}

std::string writtenIdentificationText(const IdentificationSummary& res, const IdentificationOutputs& o,
                                      const WrittenIdentification& w, const MeasurementPlan* plan) {
    std::string text;
    const TextOut out(text);
    // A model that does not fit says so before anything else of the result.
    if (res.report && !res.report->adequacy.fits) out("WARNING: {}\n", res.report->adequacy.message);
    out("{} -> {}{}{}\n", res.briefReport(), o.deviations, o.merge.empty() ? "" : " (merged into " + o.merge + ")",
        o.report.empty() ? "" : ", report -> " + o.report);
    for (const std::string& l : w.mergeLines) out("merge: {}\n", l);
    text += res.resultReport();
    circularTestTable(out, w.runs);
    importLines(out, res, plan);
    return text;
}

}  // namespace cnccomp::app
