// cnccomp identify: deviations from ball-bar measurements — general least squares on the raw traces (default,
// issue 3) or the closed-form formulas of seed 000 (--method closed-form).
#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>

#include <fmt/format.h>

#include "cli/command.hpp"
#include "cli/print.hpp"
#include "cnccomp/closed_form.hpp"
#include "cnccomp/error.hpp"
#include "cnccomp/identification/eccentricity_observation.hpp"
#include "cnccomp/identification/lsq.hpp"
#include "cnccomp/identification/measured_observations.hpp"
#include "cnccomp/identification/parameters.hpp"
#include "cnccomp/identification/plan_observations.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/eccentricity_csv.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "cnccomp/io/output_set.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "cnccomp/io/report_json.hpp"
#include "cnccomp/io/text_util.hpp"
#include "cnccomp/io/trace_csv.hpp"
#include "cnccomp/report/html_report.hpp"
#include "cnccomp/report/identification_report.hpp"

namespace cnccomp::cli {
namespace {

struct Options {
    std::string method = "least-squares";
    std::string machine, eccentricities, traces, plan, out;
    int refine = 3;
    // least squares
    std::string params = "all", report, solver = "lm", bounds, start, observe = "traces";
    std::string reportControllers, reportGrid, reportPlane = "XY";
    int monteCarlo = 0, maxIterations = 50;
    unsigned long seed = 1;
    double rankTolerance = 1e-7;
};

void runClosedForm(const Options& o, const MachineModel& m) {
    refuseToOverwrite(o.out, {o.machine, o.eccentricities, o.plan});
    std::vector<EccentricityRow> rows;
    if (!o.eccentricities.empty()) {
        if (!o.traces.empty()) throw ModelError("give either --eccentricities or --traces with --plan, not both");
        rows = readEccentricityCsv(o.eccentricities);
    } else {
        if (o.traces.empty() || o.plan.empty())
            throw ModelError("closed form needs --eccentricities E.csv, or --traces DIR with --plan P.xml");
        const MeasurementPlan plan = readPlanXml(o.plan);
        checkPlanMachine(plan, o.plan, m.name);
        rows = eccentricitiesFromTraces(m, plan.runs, readRunTraces(o.traces, plan.runs));
    }
    if (o.refine < 0 || o.refine > 20) throw ModelError("--refine takes 0..20 passes");
    const DeviationSet d = identifyClosedForm(m, rows, {o.refine, 1.0});
    writeDeviationCsv(o.out, d);
    fmt::print("identified {} deviations of '{}' (closed form, seed 000 eq. (17)-(28)) -> {}\n",
               std::count(d.present.begin(), d.present.end(), 1), m.name, o.out);
    printDeviations(d, nullptr);
}

/// "dxBT=-20:10, EB0B=-5:5" (µm for lengths, arcsec for angles) → bounds in internal units.
std::vector<ParameterBound> parseBounds(const MachineModel& m, const std::string& text) {
    std::vector<ParameterBound> out;
    size_t pos = 0;
    while (pos < text.size()) {
        size_t end = text.find(',', pos);
        if (end == std::string::npos) end = text.size();
        const std::string item(trim(std::string_view(text).substr(pos, end - pos)));
        pos = end + 1;
        if (item.empty()) continue;
        const size_t eq = item.find('='), colon = item.find(':', eq == std::string::npos ? 0 : eq);
        if (eq == std::string::npos || colon == std::string::npos)
            throw ModelError(fmt::format("--bounds item '{}': expected NAME=LOWER:UPPER (um or arcsec)", item));
        const std::string name(trim(std::string_view(item).substr(0, eq)));
        const auto lo = parseNumber(trim(std::string_view(item).substr(eq + 1, colon - eq - 1)));
        const auto hi = parseNumber(trim(std::string_view(item).substr(colon + 1)));
        if (!lo || !hi) throw ModelError(fmt::format("--bounds item '{}': bounds must be numbers", item));
        std::string base = name.substr(0, name.find('['));
        const int di = m.deviationIndex(base);
        // Nuisance names ("run.xT") are lengths; deviations take their own unit.
        const double unit = di >= 0 && m.deviations[di].isAngle() ? kArcsec : kUm;
        if (di < 0 && name.find('.') == std::string::npos)
            throw ModelError(fmt::format("--bounds: unknown deviation '{}' for machine '{}'", name, m.name));
        out.push_back({name, *lo * unit, *hi * unit});
    }
    return out;
}

std::string cell(double v, double scale, int width = 10, int prec = 4) {
    return std::isfinite(v) ? fmt::format("{:{}.{}f}", v / scale, width, prec) : fmt::format("{:>{}}", "-", width);
}

void printReport(const IdentificationReport& r) {
    fmt::print("{}: {} after {} iteration(s); cost {:.6g} -> {:.6g} um^2; rank {}/{}, condition number {:.4g}, "
               "sigma {} um\n",
               r.solver, r.termination, r.iterations, r.costBefore, r.costAfter, r.rank, r.unknowns,
               r.conditionNumber, std::isfinite(r.sigma) ? fmt::format("{:.4f}", r.sigma / kUm) : "-");
    const bool mc = r.monteCarloSamples > 0;
    fmt::print("{:<14} {:<8} {:>12} {:>10} {:>10} {:>10}{}  {}\n", "name", "alias", "value", "std", "low95", "high95",
               mc ? fmt::format(" {:>10} {:>10} {:>10}", "mc std", "mc low95", "mc high95") : "", "unit");
    for (const ParameterEstimate& p : r.parameters) {
        const double s = p.displayScale();
        if (!p.identified) {
            fmt::print("{:<14} {:<8} {:>12} {:>10} {:>10} {:>10}  {}\n", p.name, p.alias, "unidentified", "-", "-", "-",
                       p.unit());
            continue;
        }
        fmt::print("{:<14} {:<8} {} {} {} {}{}  {}\n", p.name, p.alias, cell(p.value, s, 12), cell(p.stddev, s),
                   cell(p.lower95, s), cell(p.upper95, s),
                   mc ? fmt::format(" {} {} {}", cell(p.mcStddev, s), cell(p.mcLower95, s), cell(p.mcUpper95, s)) : "",
                   p.unit());
    }
    if (!r.identifiable.empty()) {
        fmt::print("identifiable combinations of the unidentified parameters (coefficients in mm, rad):\n");
        for (const Combination& c : r.identifiable)
            fmt::print("  {} = {} ± {} {}  (identifiable, not each term)\n", c.text,
                       cell(c.value, c.angle ? kArcsec : kUm, 0), cell(c.stddev, c.angle ? kArcsec : kUm, 0),
                       c.angle ? "arcsec" : "um");
    }
    if (!r.unobservable.empty()) {
        fmt::print("directions these measurements cannot see:\n");
        for (const Combination& c : r.unobservable) fmt::print("  {}\n", c.text);
    }
    fmt::print("{:<18} {:>8} {:>14} {:>14}\n", "run", "samples", "rms before um", "rms after um");
    for (const RunResidual& rr : r.runs)
        fmt::print("{:<18} {:>8} {:>14.4f} {:>14.4f}\n", rr.run, rr.samples, rr.rmsBefore / kUm, rr.rmsAfter / kUm);
    for (const std::string& w : r.warnings) fmt::print("warning: {}\n", w);
}

/// --report R.html / R.htm: the HTML report; anything else: the JSON solver report.
bool htmlReport(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return ext == ".html" || ext == ".htm";
}

/// ISO 230-4 figures of every ball-bar run, as measured and with the identified deviations compensated.
void printCircularTests(const std::vector<report::RunSection>& runs) {
    if (runs.empty()) return;
    fmt::print("ISO 230-4 circular test figures (um; after = identified deviations compensated):\n");
    fmt::print("{:<18} {:<7} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9} {:>12} {:>9} {:>9}\n", "run", "passes", "G before",
               "G after", "Fmax bef", "Fmin bef", "Fmax aft", "Fmin aft", "mean R mm", "H before", "H after");
    const auto um = [](double v) { return std::isfinite(v) ? fmt::format("{:9.3f}", v / kUm) : fmt::format("{:>9}", "-"); };
    for (const report::RunSection& r : runs) {
        std::string passes;
        for (const report::PolarPass& p : r.passes) passes += p.direction > 0 ? "+" : "-";
        fmt::print("{:<18} {:<7} {} {} {} {} {} {} {:12.5f} {} {}\n", r.name, passes, um(r.before.G), um(r.after.G),
                   um(r.before.Fmax), um(r.before.Fmin), um(r.after.Fmax), um(r.after.Fmin), r.before.meanRadius, um(r.before.H),
                   um(r.after.H));
    }
}

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

void runLeastSquares(const Options& o, const MachineModel& m) {
    if (!o.eccentricities.empty())
        throw ModelError("least squares works on the raw traces: give --traces DIR and --plan P.xml (eccentricities are "
                         "for --method closed-form)");
    if (o.traces.empty() || o.plan.empty()) throw ModelError("least squares needs --traces DIR and --plan P.xml");
    if ((!o.reportControllers.empty() || !o.reportGrid.empty()) && !htmlReport(o.report))
        throw ModelError("--report-controllers and --report-grid belong to an HTML report: give --report R.html");
    refuseToOverwrite(o.out, {o.machine, o.plan, o.start});
    if (!o.report.empty()) {
        refuseToOverwrite(o.report, {o.machine, o.plan, o.start, o.out});
    }
    const MeasurementPlan plan = readPlanXml(o.plan);
    checkPlanMachine(plan, o.plan, m.name);
    Observations obs;
    MeasuredRuns measured;
    if (o.observe == "eccentricity") {
        if (plan.runCount() != plan.runs.size())
            throw ModelError("--observe eccentricity works on ball-bar <run> elements only");
        obs = eccentricityObservations(m, plan.runs, readRunTraces(o.traces, plan.runs));
    } else if (o.observe == "traces") {
        measured = measuredObservations(m, plan, o.traces);
        obs = std::move(measured.observations);
    } else {
        throw ModelError(fmt::format("unknown --observe '{}' (traces, eccentricity)", o.observe));
    }
    IdentifyOptions io;
    io.deviations = parseDeviationList(m, o.params);
    io.solver = o.solver;
    io.maxIterations = o.maxIterations;
    io.rankTolerance = o.rankTolerance;
    io.monteCarlo = o.monteCarlo;
    io.seed = o.seed;
    io.bounds = parseBounds(m, o.bounds);
    if (!o.start.empty()) io.start = readDeviationCsv(o.start, m);
    const IdentificationResult r = identify(m, obs, io);
    // All outputs or none.
    OutputSet outputs({o.machine, o.plan, o.start});
    outputs.add(o.out, formatDeviationCsv(r.deviations));
    std::vector<report::RunSection> runs;
    if (o.observe == "traces") {
        measured.observations = std::move(obs);
        runs = report::measuredRunSections(m, plan, measured, r);
    }
    if (!o.report.empty() && htmlReport(o.report)) {
        report::ReportData d;
        d.title = fmt::format("Identification of {}", m.name);
        d.machine = m.name;
        d.facts = {{"machine file", o.machine}, {"plan", o.plan}, {"traces", o.traces}, {"deviations written", o.out},
                   {"solver", fmt::format("{}: {} after {} iteration(s)", r.report.solver, r.report.termination, r.report.iterations)},
                   {"fit", fmt::format("{} samples, rank {}/{}, condition number {:.4g}, sigma {:.4f} µm", r.report.observations,
                                       r.report.rank, r.report.unknowns, r.report.conditionNumber, r.report.sigma / kUm)}};
        d.warnings = r.report.warnings;
        d.runs = runs;
        d.deviations = report::deviationRows(r.report);
        for (const Combination& c : r.report.identifiable) d.combinations.push_back(c.text);
        report::MapOptions mo;
        mo.grid = o.reportGrid;
        mo.plane = o.reportPlane;
        mo.toolLength = plan.runs.empty() ? 0.0 : plan.runs.front().RB;
        report::addCompensationSections(d, m, r.deviations, splitList(o.reportControllers), mo);
        report::stageHtmlReport(outputs, o.report, d);
    } else if (!o.report.empty()) {
        outputs.add(o.report, formatReportJson(r.report));
    }
    outputs.commit();
    const auto identified = std::count_if(io.deviations.begin(), io.deviations.end(),
                                          [&](int i) { return r.deviations.present[i] != 0; });
    fmt::print("identified {} of {} requested deviations of '{}' (least squares on {} samples of {} runs) -> {}{}\n",
               identified, io.deviations.size(), m.name, r.report.observations, plan.runCount(), o.out,
               o.report.empty() ? "" : ", report -> " + o.report);
    printReport(r.report);
    printCircularTests(runs);
}

void run(const Options& o) {
    const MachineModel m = readMachineXml(o.machine);
    if (o.method == "closed-form") return runClosedForm(o, m);
    if (o.method != "least-squares" && o.method != "lsq")
        throw ModelError(fmt::format("unknown --method '{}' (least-squares, closed-form)", o.method));
    runLeastSquares(o, m);
}

const RegisterCommand reg([](CLI::App& app) {
    auto o = std::make_shared<Options>();
    auto* c = app.add_subcommand("identify", "Identify the machine's deviations from ball-bar measurements");
    c->add_option("--method", o->method,
                  "least-squares (exact model, raw traces) or closed-form (seed 000 eq. (17)-(28))")
        ->capture_default_str();
    c->add_option("--machine", o->machine, "machine description XML")->required()->check(CLI::ExistingFile);
    c->add_option("--eccentricities", o->eccentricities, "eccentricity CSV (closed form)")->check(CLI::ExistingFile);
    c->add_option("--traces", o->traces, "folder of trace CSVs, one <run>.csv per run")->check(CLI::ExistingDirectory);
    c->add_option("--plan", o->plan, "measurement plan XML")->check(CLI::ExistingFile);
    c->add_option("--out", o->out, "deviation CSV to write")->required();
    c->add_option("--refine", o->refine,
                  "closed form: defect-correction passes on the exact model (0 = the paper's formulas only)")
        ->capture_default_str();
    c->add_option("--params", o->params, "least squares: deviations to identify, ISO names or aliases (comma list), or all")
        ->capture_default_str();
    c->add_option("--observe", o->observe,
                  "least squares: traces (every raw sample) or eccentricity (fitted circle centres of ball-bar runs)")
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
    c->add_option("--bounds", o->bounds, "NLopt: NAME=LOWER:UPPER,... in um / arcsec (default +-1000)");
    c->add_option("--start", o->start,
                  "least squares: deviation CSV with starting values; deviations not in --params keep these values")
        ->check(CLI::ExistingFile);
    c->add_option("--monte-carlo", o->monteCarlo, "least squares: number of resampled solutions for sampled intervals");
    c->add_option("--seed", o->seed, "random seed for --monte-carlo");
    c->add_option("--max-iterations", o->maxIterations, "least squares: iteration limit")->capture_default_str();
    c->add_option("--rank-tolerance", o->rankTolerance,
                  "relative singular value below which a direction counts as unobservable")
        ->capture_default_str();
    c->callback([o] { run(*o); });
});

}  // namespace
}  // namespace cnccomp::cli
