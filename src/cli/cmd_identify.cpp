// cnccomp identify: the machine's deviations from any measurement plan. The kinds of runs in the plan choose what is
// measured (ball-bar circles, head patterns, R-test location or tables, DBB5; --measure overrides), --method how:
// least squares on the exact model (default, the most accurate) or the formulas of the paper the measurement comes
// from. Every output is written after every computation succeeded.
#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "cli/command.hpp"
#include "app/identify.hpp"
#include "cli/print.hpp"
#include "cnccomp/error.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/linear_circle_json.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "cnccomp/io/output_set.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "cnccomp/io/report_json.hpp"
#include "cnccomp/io/text_util.hpp"
#include "cnccomp/laser_deviation.hpp"
#include "app/report/html_report.hpp"
#include "app/report/identification_report.hpp"
#include "app/report/linear_circle_report.hpp"

namespace cnccomp::cli {
using namespace cnccomp::identification;
using namespace cnccomp::io;
using namespace cnccomp::measurement;
namespace {

struct Options {
    app::IdentificationOptions request;
    std::string method = "least-squares", observe = "traces", solver = "lm";  ///< as typed; parsed into `request`
    std::string machine, plan, out, report, truth, merge;
    std::string anglesOut, volumetricOut, isoOut, profileOut;
    std::string reportControllers, reportGrid, reportPlane = "XY";
};

std::vector<std::string> splitList(const std::string& text) {
    std::vector<std::string> out;
    size_t pos = 0;
    while (pos <= text.size()) {
        const size_t end = std::min(text.find(',', pos), text.size());
        const std::string item(trim(std::string_view(text).substr(pos, end - pos)));
        if (!item.empty()) out.push_back(item);
        pos = end + 1;
    }
    return out;
}

/// ISO 230-4 figures of every ball-bar run, as measured and with the identified deviations compensated.
void printCircularTests(const std::vector<app::report::RunSection>& runs) {
    if (runs.empty()) return;
    fmt::print("ISO 230-4 circular test figures (um; after = identified deviations compensated):\n");
    fmt::print("{:<18} {:<7} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9} {:>12} {:>9} {:>9}\n", "run", "passes", "G before",
               "G after", "Fmax bef", "Fmin bef", "Fmax aft", "Fmin aft", "mean R mm", "H before", "H after");
    const auto um = [](double v) { return std::isfinite(v) ? fmt::format("{:9.3f}", v / kUm) : fmt::format("{:>9}", "-"); };
    for (const app::report::RunSection& r : runs) {
        std::string passes;
        for (const app::report::PolarPass& p : r.passes) passes += p.direction > 0 ? "+" : "-";
        fmt::print("{:<18} {:<7} {} {} {} {} {} {} {:12.5f} {} {}\n", r.name, passes, um(r.before.G), um(r.after.G),
                   um(r.before.Fmax), um(r.before.Fmin), um(r.after.Fmax), um(r.after.Fmin), r.before.meanRadius,
                   um(r.before.H), um(r.after.H));
    }
}

void run(Options o) {
    // The options as typed, parsed and checked before any file is read (the façade checks them again).
    app::IdentificationOptions& r = o.request;
    r.approach = app::parseApproach(o.method);
    r.observe = app::parseObserve(o.observe);
    r.solver = app::parseSolver(o.solver);
    app::validateOptions(r);
    const MachineModel m = readMachineXml(o.machine);
    std::optional<MeasurementPlan> plan;
    if (!o.plan.empty()) {
        plan = readPlanXml(o.plan);
        checkPlanMachine(*plan, o.plan, m.name);
        choosePlanMethod(*plan, r.measure);
    } else if (!r.measure.empty() && r.measure != "ball-bar") {
        throw ModelError("--measure needs the plan (--plan P.xml)");
    }
    const bool html = !o.report.empty() && app::report::isHtmlPath(o.report);
    if ((!o.reportControllers.empty() || !o.reportGrid.empty()) && !html)
        throw ModelError("--report-controllers and --report-grid belong to an HTML report: give --report R.html");
    if (!o.profileOut.empty() && !r.components) throw ModelError("--profile-out needs --components");
    // Outputs: never an input, never twice.
    const std::vector<std::pair<std::string, std::string>> outputs{
        {"--out", o.out}, {"--report", o.report}, {"--angles-out", o.anglesOut}, {"--volumetric-out", o.volumetricOut},
        {"--iso-out", o.isoOut}, {"--profile-out", o.profileOut}};
    for (size_t i = 0; i < outputs.size(); ++i) {
        if (outputs[i].second.empty()) continue;
        refuseToOverwrite(outputs[i].second, {o.machine, o.plan, o.truth, r.start, r.eccentricities, o.merge});
        for (size_t j = 0; j < i; ++j)
            if (outputs[j].second == outputs[i].second)
                throw ModelError(fmt::format("{} and {} name the same file '{}'", outputs[j].first, outputs[i].first,
                                             outputs[i].second));
    }
    if (!o.volumetricOut.empty() && r.volumetricRun.empty()) throw ModelError("--volumetric-out needs --volumetric RUN");
    const std::optional<DeviationSet> truth =
        o.truth.empty() ? std::nullopt : std::optional<DeviationSet>(readDeviationCsv(o.truth, m));

    const app::IdentificationSummary res = app::identify(m, plan ? &*plan : nullptr, r);
    // What the method found as it worked, as before any file is written.
    fmt::print("{}", res.methodTables);
    if (!o.report.empty() && !res.report && !res.circles)
        throw ModelError(fmt::format("--report: the {} of '{}' writes no least-squares report",
                                     res.formulas ? "formulas" : "method", planMethodName(res.kind)));
    std::vector<std::pair<std::string, const app::ExtraOutput*>> extras;
    for (const auto& [option, path] : outputs) {
        if (path.empty() || option == "--out" || option == "--report") continue;
        const auto it = std::find_if(res.extras.begin(), res.extras.end(), [&](const app::ExtraOutput& e) { return e.option == option; });
        if (it == res.extras.end())
            throw ModelError(fmt::format("{} does not apply to the {} method", option, planMethodName(res.kind)));
        extras.emplace_back(path, &*it);
    }
    // Ball-bar runs of a least-squares solution on measured traces: ISO 230-4 figures before / after.
    std::vector<app::report::RunSection> runs;
    if (res.measured && res.result && plan) runs = app::report::measuredRunSections(m, *plan, *res.measured, *res.result);

    // Everything is computed: stage every output, then commit them together (all or nothing).
    OutputSet staged({o.machine, o.plan, o.truth, r.start, r.eccentricities, o.merge});
    // --merge: the identified deviations replace theirs in an existing set (e.g. the laser's positioning components
    // and a rotary-axis identification), the others are kept (laser_deviation.hpp, mergeDeviations).
    // A reversal value this run did not determine keeps the base's (said below, reversalMergeLines).
    std::vector<std::string> mergeLines;
    if (o.merge.empty()) {
        staged.add(o.out, formatDeviationCsv(res.deviations));
    } else {
        const DeviationSet base = readDeviationCsv(o.merge, m);
        mergeLines = reversalMergeLines(base, res.deviations, "this identification");
        staged.add(o.out, formatDeviationCsv(mergeDeviations(base, res.deviations)));
    }
    if (res.circles && html) {
        if (!o.reportControllers.empty() || !o.reportGrid.empty())
            throw ModelError("--report-controllers and --report-grid: the circles of the linear axes write no maps or "
                             "controller sections yet");
        app::report::stageHtmlReport(staged, o.report,
                                app::report::linearCircleReportData(m.name, *res.circles,
                                                               {{"machine file", o.machine}, {"plan", o.plan},
                                                                {"traces", r.traces}, {"deviations written", o.out},
                                                                {"identification", res.summary}}));
    } else if (res.circles && !o.report.empty()) {
        staged.add(o.report, formatLinearCircleJson(m.name, *res.circles));
    } else if (html) {
        const IdentificationReport& rep = *res.report;
        app::report::ReportData d;
        d.title = fmt::format("Identification of {}", m.name);
        d.machine = m.name;
        d.facts = {{"machine file", o.machine}, {"plan", o.plan}, {"traces", r.traces}, {"deviations written", o.out},
                   {"solver", fmt::format("{}: {} after {} iteration(s)", rep.solver, rep.termination, rep.iterations)},
                   {"fit", fmt::format("{} samples, rank {}/{}, condition number {:.4g}, sigma {:.4f} µm", rep.observations,
                                       rep.rank, rep.unknowns, rep.conditionNumber, rep.sigma / kUm)}};
        if (!rep.stages.empty()) d.facts.push_back({"fitted in two stages", rep.stages});
        if (!rep.adequacy.fits) d.alarms.push_back("WARNING: " + rep.adequacy.message);
        for (const std::string& w : rep.warnings)
            if (rep.adequacy.fits || w != rep.adequacy.message) d.warnings.push_back(w);
        d.afterNote = "the run with the identified deviations compensated";
        d.runs = runs;
        d.deviations = app::report::deviationRows(rep);
        for (const Combination& c : rep.identifiable) d.combinations.push_back(c.text);
        app::report::MapOptions mo;
        mo.grid = o.reportGrid;
        mo.plane = o.reportPlane;
        mo.toolLength = plan && !plan->runs.empty() ? plan->runs.front().RB : 0.0;
        app::report::addCompensationSections(d, m, res.deviations, splitList(o.reportControllers), mo);
        app::report::stageHtmlReport(staged, o.report, d);
    } else if (!o.report.empty()) {
        staged.add(o.report, formatReportJson(*res.report));
    }
    for (const auto& [path, e] : extras) staged.add(path, e->write);
    staged.commit();

    // A model that does not fit says so before anything else of the result.
    if (res.report && !res.report->adequacy.fits) fmt::print("WARNING: {}\n", res.report->adequacy.message);
    fmt::print("{} -> {}{}{}\n", res.briefReport(), o.out, o.merge.empty() ? "" : " (merged into " + o.merge + ")",
               o.report.empty() ? "" : ", report -> " + o.report);
    for (const std::string& l : mergeLines) fmt::print("merge: {}\n", l);
    fmt::print("{}", res.resultReport());
    printCircularTests(runs);
    if (res.measured)
        for (size_t i = 0; i < res.measured->ballbar.size() && plan; ++i) {
            const TraceImportSummary& s = res.measured->ballbar[i].summary;
            if (s.feedEstimate > 0)
                fmt::print("feed from the data, run {}: {:.1f} mm/min (plan {:g}, {:+.2f} %, allowed ±{:.2f} %)\n",
                           plan->runs[i].name, s.feedEstimate, plan->runs[i].capture.feed,
                           100 * (s.feedEstimate / plan->runs[i].capture.feed - 1), 100 * s.feedTolerance);
            if (s.binnedFrom > 0)
                fmt::print("run {}: {} samples averaged into {} bins of the plan's {:g}° step\n", plan->runs[i].name,
                           s.binnedFrom, s.binnedInto, std::abs(plan->runs[i].stepDeg));
        }
    printDeviations(res.deviations, truth ? &*truth : nullptr);
}

const RegisterCommand reg([](CLI::App& app) {
    auto o = std::make_shared<Options>();
    app::IdentificationOptions& r = o->request;
    auto* c = app.add_subcommand(
        "identify",
        "Identify the machine's deviations from the runs of a plan. The plan's runs choose what is measured: ball-bar "
        "circles, head patterns (absolute ball bar, two tool lengths), R-test location or tables, DBB5 circles, ball-bar circles of "
        "the linear axes (<circle>, ISO 230-4: diagnostics ranked by their share of the circularity)");
    c->add_option("--machine", o->machine, "machine description XML")->required()->check(CLI::ExistingFile);
    c->add_option("--plan", o->plan, "measurement plan XML")->check(CLI::ExistingFile);
    c->add_option("--traces", r.traces, "folder of the measured runs, one <run>.csv per run")->check(CLI::ExistingDirectory);
    c->add_option("--probe-log", r.probeLog, "sphere plans: the probe result file in the --traces folder")
        ->capture_default_str();
    c->add_option("--out", o->out, "deviation CSV to write (ISO names and values, paper aliases)")->required();
    c->add_option("--method", o->method,
                  "least-squares (exact model, every sample; the most accurate) or formulas (the paper's formulas of the "
                  "measurement, e.g. the ball-bar eccentricity formulas; closed-form is the same)")
        ->capture_default_str();
    c->add_option("--measure", r.measure,
                  "override what the plan measures: ball-bar, head-patterns, rtest-location, rtest-tables, dbb5, mixed, circle");
    c->add_option("--eccentricities", r.eccentricities, "ball-bar formulas: eccentricity CSV instead of --traces/--plan")
        ->check(CLI::ExistingFile);
    c->add_option("--refine", r.refine,
                  "formulas: refinement passes on the exact model (0 = the printed formulas; default 3 for ball-bar "
                  "eccentricities, 4 for R-test and DBB5 fits)");
    c->add_option("--params", r.params,
                  "least squares: deviations to identify, ISO names or aliases (comma list) or all; default: all for "
                  "ball-bar and mixed plans, the eleven location and squareness errors for R-test location and DBB5");
    c->add_flag("--one-stage", r.oneStage,
                "least squares: fit every run at once (default: what the runs moving only linear axes determine, e.g. "
                "the squareness from the DBB5 XY/YZ/ZX circles, is fitted from them first, then held)");
    c->add_option("--observe", o->observe,
                  "least squares on ball-bar runs: traces (every raw sample) or eccentricity (fitted circle centres)")
        ->capture_default_str();
    c->add_option("--report", o->report,
                  "least squares: report to write: R.json (solver report) or R.html (page with polar plots, ISO 230-4 "
                  "figures, deviations, maps; SVGs and R.summary.json beside it)");
    c->add_option("--report-controllers", o->reportControllers,
                  "HTML report: controllers (comma list) whose coverage and predicted residual to show");
    c->add_option("--report-grid", o->reportGrid, "HTML report: map grid as for cnccomp map (default: X, Y over the travel)");
    c->add_option("--report-plane", o->reportPlane, "HTML report: map plane as for cnccomp map --plane")->capture_default_str();
    c->add_option("--solver", o->solver, "least squares: lm (Levenberg-Marquardt) or nlopt:<ALGORITHM>, e.g. nlopt:LD_SLSQP")
        ->capture_default_str();
    c->add_option("--bounds", r.bounds, "NLopt: ISO-NAME=LOWER:UPPER,... in um / arcsec (default +-1000)");
    c->add_option("--start", r.start, "least squares: deviation CSV with starting values; deviations not estimated keep them")
        ->check(CLI::ExistingFile);
    c->add_option("--monte-carlo", r.monteCarlo, "least squares: number of resampled solutions for sampled intervals");
    c->add_option("--seed", r.seed, "random seed for --monte-carlo");
    c->add_option("--max-iterations", r.maxIterations, "least squares: iteration limit")->capture_default_str();
    c->add_option("--rank-tolerance", r.rankTolerance,
                  "relative singular value below which a direction counts as unobservable")
        ->capture_default_str();
    c->add_option("--outer", r.outer, "R-test / DBB5: tilting (outer) rotary axis (default: the machine's first table axis)");
    c->add_option("--inner", r.inner, "R-test / DBB5: rotary table (inner) axis (default: the machine's second table axis)");
    c->add_option("--angles-out", o->anglesOut, "head patterns: CSV of the head's five errors at every measured angle");
    c->add_option("--volumetric", r.volumetricRun,
                  "R-test location: run along which to compare the measured displacement with the identified model's");
    c->add_option("--volumetric-out", o->volumetricOut, "CSV of that comparison");
    c->add_option("--iso-out", o->isoOut, "DBB5: CSV of the ISO 230-4 figures of every run");
    c->add_flag("--components", r.components,
                "DBB5: also the component errors (error motions) of the rotary table axis from its on-axis runs, as tables");
    c->add_option("--profile-out", o->profileOut, "DBB5 --components: CSV of the component profiles over angle (bed frame, um / arcsec)");
    c->add_option("--merge", o->merge,
                  "deviation CSV the identified deviations are merged into (its others kept), written to --out")
        ->check(CLI::ExistingFile);
    c->add_option("--truth", o->truth, "deviation CSV to print next to the result")->check(CLI::ExistingFile);
    c->callback([o] { run(*o); });
});

}  // namespace
}  // namespace cnccomp::cli
