// cnccomp identify: the machine's deviations from any measurement plan. The kinds of runs in the plan choose what is
// measured (ball-bar circles, head patterns, R-test location or tables, DBB5; --measure overrides), --method how:
// least squares on the exact model (default, the most accurate) or the formulas of the paper the measurement comes
// from. Every output is written after every computation succeeded.
#include <algorithm>

#include <fmt/format.h>

#include "cli/command.hpp"
#include "cli/identify_methods.hpp"
#include "cli/print.hpp"
#include "cnccomp/error.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "cnccomp/io/report_json.hpp"
#include "cnccomp/io/text_util.hpp"

namespace cnccomp::cli {
namespace {

struct Options {
    IdentifyRequest request;
    std::string method = "least-squares", measure, machine, plan, out, report, truth;
    std::string anglesOut, volumetricOut, isoOut;
};

void run(Options o) {
    const MachineModel m = readMachineXml(o.machine);
    IdentifyRequest& r = o.request;
    r.machine = &m;
    if (o.method == "formulas" || o.method == "closed-form") r.formulas = true;
    else if (o.method != "least-squares" && o.method != "lsq")
        throw ModelError(fmt::format("unknown --method '{}' (least-squares, formulas)", o.method));
    std::optional<MeasurementPlan> plan;
    if (!o.plan.empty()) {
        plan = readPlanXml(o.plan);
        r.plan = &*plan;
        r.kind = choosePlanMethod(*plan, o.measure);
    } else if (!o.measure.empty() && o.measure != "ball-bar") {
        throw ModelError("--measure needs the plan (--plan P.xml)");
    }
    // Outputs: never an input, never twice.
    const std::vector<std::pair<std::string, std::string>> outputs{
        {"--out", o.out}, {"--report", o.report}, {"--angles-out", o.anglesOut}, {"--volumetric-out", o.volumetricOut},
        {"--iso-out", o.isoOut}};
    for (size_t i = 0; i < outputs.size(); ++i) {
        if (outputs[i].second.empty()) continue;
        refuseToOverwrite(outputs[i].second, {o.machine, o.plan, o.truth, r.start, r.eccentricities});
        for (size_t j = 0; j < i; ++j)
            if (outputs[j].second == outputs[i].second)
                throw ModelError(fmt::format("{} and {} name the same file '{}'", outputs[j].first, outputs[i].first,
                                             outputs[i].second));
    }
    if (!o.volumetricOut.empty() && r.volumetricRun.empty()) throw ModelError("--volumetric-out needs --volumetric RUN");
    const std::optional<DeviationSet> truth =
        o.truth.empty() ? std::nullopt : std::optional<DeviationSet>(readDeviationCsv(o.truth, m));

    IdentifyOutcome res = runIdentification(r);
    if (!o.report.empty() && !res.report)
        throw ModelError(fmt::format("--report: the {} of '{}' writes no least-squares report",
                                     r.formulas ? "formulas" : "method", planMethodName(r.kind)));
    std::vector<std::pair<std::string, const ExtraOutput*>> extras;
    for (const auto& [option, path] : outputs) {
        if (path.empty() || option == "--out" || option == "--report") continue;
        const auto it = std::find_if(res.extras.begin(), res.extras.end(), [&](const ExtraOutput& e) { return e.option == option; });
        if (it == res.extras.end())
            throw ModelError(fmt::format("{} does not apply to the {} method", option, planMethodName(r.kind)));
        extras.emplace_back(path, &*it);
    }

    // Everything is computed: write.
    writeDeviationCsv(o.out, res.deviations);
    if (!o.report.empty()) writeReportJson(o.report, *res.report);
    for (const auto& [path, e] : extras) e->write(path);

    fmt::print("{} -> {}\n", res.summary, o.out);
    if (res.report) printReport(*res.report);
    printDeviations(res.deviations, truth ? &*truth : nullptr);
}

const RegisterCommand reg([](CLI::App& app) {
    auto o = std::make_shared<Options>();
    IdentifyRequest& r = o->request;
    auto* c = app.add_subcommand(
        "identify",
        "Identify the machine's deviations from the runs of a plan. The plan's runs choose what is measured: ball-bar "
        "circles, head patterns (absolute ball bar, two tool lengths), R-test location or tables, DBB5 circles");
    c->add_option("--machine", o->machine, "machine description XML")->required()->check(CLI::ExistingFile);
    c->add_option("--plan", o->plan, "measurement plan XML")->check(CLI::ExistingFile);
    c->add_option("--traces", r.traces, "folder of the measured runs, one <run>.csv per run")->check(CLI::ExistingDirectory);
    c->add_option("--out", o->out, "deviation CSV to write (ISO names and values, paper aliases)")->required();
    c->add_option("--method", o->method,
                  "least-squares (exact model, every sample; the most accurate) or formulas (the paper's formulas of the "
                  "measurement, e.g. the ball-bar eccentricity formulas; closed-form is the same)")
        ->capture_default_str();
    c->add_option("--measure", o->measure,
                  "override what the plan measures: ball-bar, head-patterns, rtest-location, rtest-tables, dbb5, mixed");
    c->add_option("--eccentricities", r.eccentricities, "ball-bar formulas: eccentricity CSV instead of --traces/--plan")
        ->check(CLI::ExistingFile);
    c->add_option("--refine", r.refine,
                  "formulas: refinement passes on the exact model (0 = the printed formulas; default 3 for ball-bar "
                  "eccentricities, 4 for R-test and DBB5 fits)");
    c->add_option("--params", r.params,
                  "least squares: deviations to identify, ISO names or aliases (comma list) or all; default: all for "
                  "ball-bar and mixed plans, the eleven location and squareness errors for R-test location and DBB5");
    c->add_option("--observe", r.observe,
                  "least squares on ball-bar runs: traces (every raw sample) or eccentricity (fitted circle centres)")
        ->capture_default_str();
    c->add_option("--report", o->report, "least squares: JSON report to write");
    c->add_option("--solver", r.solver, "least squares: lm (Levenberg-Marquardt) or nlopt:<ALGORITHM>, e.g. nlopt:LD_SLSQP")
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
    c->add_option("--truth", o->truth, "deviation CSV to print next to the result")->check(CLI::ExistingFile);
    c->callback([o] { run(*o); });
});

}  // namespace
}  // namespace cnccomp::cli
