// cnccomp identify: the machine's deviations from any measurement plan. The kinds of runs in the plan choose what is
// measured (ball-bar circles, head patterns, R-test location or tables, DBB5; --measure overrides), --method how:
// least squares on the exact model (default, the most accurate) or the formulas of the paper the measurement comes
// from. Every output is written after every computation succeeded, all or nothing (src/app/identify_outputs.hpp);
// this file parses the options, calls the application layer and prints.
#include <optional>
#include <string>

#include <fmt/format.h>

#include "app/identify.hpp"
#include "app/identify_outputs.hpp"
#include "cli/command.hpp"
#include "cli/print.hpp"
#include "cnccomp/error.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "cnccomp/io/plan_xml.hpp"

namespace cnccomp::cli {
using namespace cnccomp::identification;
using namespace cnccomp::io;
using namespace cnccomp::measurement;
namespace {

struct Options {
    app::IdentificationOptions request;
    app::IdentificationOutputs outputs;
    std::string method = "least-squares", observe = "traces", solver = "lm";  ///< as typed; parsed into `request`
    std::string truth;
};

void run(Options o) {
    // The options as typed, parsed and checked before any file is read (the façade checks them again).
    app::IdentificationOptions& r = o.request;
    app::IdentificationOutputs& out = o.outputs;
    r.approach = app::parseApproach(o.method);
    r.observe = app::parseObserve(o.observe);
    r.solver = app::parseSolver(o.solver);
    app::validateOptions(r);
    const MachineModel m = readMachineXml(out.machineFile);
    std::optional<MeasurementPlan> plan;
    if (!out.planFile.empty()) {
        plan = readPlanXml(out.planFile);
        checkPlanMachine(*plan, out.planFile, m.name);
        choosePlanMethod(*plan, r.measure);
    } else if (!r.measure.empty() && r.measure != "ball-bar") {
        throw ModelError("--measure needs the plan (--plan P.xml)");
    }
    out.otherInputs = {o.truth};
    app::checkOutputRequests(out, r);  // never an input, never twice; before any measurement is read
    const std::optional<DeviationSet> truth =
        o.truth.empty() ? std::nullopt : std::optional<DeviationSet>(readDeviationCsv(o.truth, m));

    const MeasurementPlan* p = plan ? &*plan : nullptr;
    const app::IdentificationSummary res = app::identify(m, p, r);
    // What the method found as it worked, as before any file is written.
    fmt::print("{}", res.methodTables);
    // Every output is written after every computation succeeded, all or nothing.
    const app::WrittenIdentification written = app::writeIdentificationOutputs(m, p, r, res, out);
    fmt::print("{}", app::writtenIdentificationText(res, out, written, p));
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
    c->add_option("--machine", o->outputs.machineFile, "machine description XML")->required()->check(CLI::ExistingFile);
    c->add_option("--plan", o->outputs.planFile, "measurement plan XML")->check(CLI::ExistingFile);
    c->add_option("--traces", r.traces, "folder of the measured runs, one <run>.csv per run")->check(CLI::ExistingDirectory);
    c->add_option("--probe-log", r.probeLog, "sphere plans: the probe result file in the --traces folder")
        ->capture_default_str();
    c->add_option("--out", o->outputs.deviations, "deviation CSV to write (ISO names and values, paper aliases)")->required();
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
    c->add_option("--report", o->outputs.report,
                  "least squares: report to write: R.json (solver report) or R.html (page with polar plots, ISO 230-4 "
                  "figures, deviations, maps; SVGs and R.summary.json beside it)");
    c->add_option("--report-controllers", o->outputs.reportControllers,
                  "HTML report: controllers (comma list) whose coverage and predicted residual to show");
    c->add_option("--report-grid", o->outputs.reportGrid, "HTML report: map grid as for cnccomp map (default: X, Y over the travel)");
    c->add_option("--report-plane", o->outputs.reportPlane, "HTML report: map plane as for cnccomp map --plane")->capture_default_str();
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
    c->add_option("--angles-out", o->outputs.anglesOut, "head patterns: CSV of the head's five errors at every measured angle");
    c->add_option("--volumetric", r.volumetricRun,
                  "R-test location: run along which to compare the measured displacement with the identified model's");
    c->add_option("--volumetric-out", o->outputs.volumetricOut, "CSV of that comparison");
    c->add_option("--iso-out", o->outputs.isoOut, "DBB5: CSV of the ISO 230-4 figures of every run");
    c->add_flag("--components", r.components,
                "DBB5: also the component errors (error motions) of the rotary table axis from its on-axis runs, as tables");
    c->add_option("--profile-out", o->outputs.profileOut, "DBB5 --components: CSV of the component profiles over angle (bed frame, um / arcsec)");
    c->add_option("--merge", o->outputs.merge,
                  "deviation CSV the identified deviations are merged into (its others kept), written to --out")
        ->check(CLI::ExistingFile);
    c->add_option("--truth", o->truth, "deviation CSV to print next to the result")->check(CLI::ExistingFile);
    c->callback([o] { run(*o); });
});

}  // namespace
}  // namespace cnccomp::cli
