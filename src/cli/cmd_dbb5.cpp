// cnccomp dbb5: DBB5 ball-bar runs (Ibaraki et al.) — ISO 230-4 circularity and mean radial error of every DBB5 run, and the location errors of
// the rotary axes and squareness of the linear axes by the paper's formulas or their least-squares equivalent (--lsq).
#include <algorithm>
#include <filesystem>
#include <ostream>

#include <fmt/format.h>

#include "cli/command.hpp"
#include "cli/print.hpp"
#include "cnccomp/error.hpp"
#include "cnccomp/identification/dbb5_observation.hpp"
#include "cnccomp/identification/lsq.hpp"
#include "cnccomp/identification/dbb5_location_errors.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "cnccomp/io/text_util.hpp"
#include "cnccomp/io/trace_csv.hpp"

namespace cnccomp::cli {
namespace {

struct Options {
    std::string machine, plan, traces, out, isoOut, truth, outer, inner;
    bool lsq = false;
    int refine = 4;
};

void run(const Options& o) {
    const MachineModel m = readMachineXml(o.machine);
    if (!o.out.empty()) refuseToOverwrite(o.out, {o.machine, o.plan, o.truth});
    if (!o.isoOut.empty()) refuseToOverwrite(o.isoOut, {o.machine, o.plan, o.truth, o.out});
    const MeasurementPlan plan = readPlanXml(o.plan);
    if (plan.dbb5Runs.empty()) throw ModelError(fmt::format("plan '{}' has no <dbb5> runs", o.plan));
    std::vector<BallbarTrace> traces;
    for (const Dbb5Run& r : plan.dbb5Runs)
        traces.push_back(readTraceCsv((std::filesystem::path(o.traces) / (r.name + ".csv")).string()));
    fmt::print("{:<14} {:>8} {:>16} {:>18} {:>10}  (ISO 230-4)\n", "run", "samples", "circularity um",
               "mean radial err um", "b2 um");
    std::vector<CircularTestResult> iso;
    for (size_t i = 0; i < traces.size(); ++i) {
        iso.push_back(evaluateCircularTest(traces[i], plan.dbb5Runs[i].LB));
        fmt::print("{:<14} {:>8} {:16.4f} {:18.4f} {:10.4f}\n", plan.dbb5Runs[i].name, iso.back().samples,
                   iso.back().circularity / kUm, iso.back().meanRadialError / kUm, iso.back().b2 / kUm);
    }
    if (!o.isoOut.empty())
        writeFileAtomically(o.isoOut, [&](std::ostream& out) {
            out << "run,samples,circularity_um,mean_radial_error_um,radial_max_um,radial_min_um,b2_um\n";
            for (size_t i = 0; i < iso.size(); ++i)
                out << fmt::format("{},{},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f}\n", plan.dbb5Runs[i].name, iso[i].samples,
                                   iso[i].circularity / kUm, iso[i].meanRadialError / kUm, iso[i].radialMax / kUm,
                                   iso[i].radialMin / kUm, iso[i].b2 / kUm);
        });
    if (o.out.empty()) return;
    const std::optional<DeviationSet> truth =
        o.truth.empty() ? std::nullopt : std::optional<DeviationSet>(readDeviationCsv(o.truth, m));
    DeviationSet d(m);
    const Dbb5LocationOptions lo{o.outer, o.inner, o.refine};
    if (o.lsq) {
        IdentifyOptions io;
        io.deviations = dbb5LocationDeviations(m, lo);
        std::sort(io.deviations.begin(), io.deviations.end());
        const IdentificationResult r = identify(m, dbb5Observations(m, plan.dbb5Runs, traces), io);
        d = r.deviations;
        fmt::print("DBB5, least squares on {} samples: rank {} of {}, {}\n", r.report.observations, r.report.rank,
                   r.report.unknowns, r.report.termination);
        for (const std::string& w : r.report.warnings) fmt::print("warning: {}\n", w);
    } else {
        const Dbb5LocationResult r = dbb5LocationErrors(m, plan.dbb5Runs, traces, lo);
        d = r.deviations;
        fmt::print("plain formulas, the paper's definitions (relative to the machine axes):\n");
        for (const Dbb5FormulaValue& v : r.formulas)
            fmt::print("  {:<18} {:>10.4f} {:<6}  {}\n", v.name, v.value / (v.angle ? kArcsec : kUm),
                       v.angle ? "arcsec" : "um", v.definition);
        fmt::print("{}: {} refinement steps on the exact model\n",
                   r.refine > 0 ? "deviations" : "deviations (plain formulas converted to the model's definitions)",
                   r.refine);
    }
    writeDeviationCsv(o.out, d);
    printDeviations(d, truth ? &*truth : nullptr);
    fmt::print("-> {}\n", o.out);
}

const RegisterCommand reg([](CLI::App& app) {
    auto o = std::make_shared<Options>();
    auto* c = app.add_subcommand("dbb5", "DBB5 ball bar: ISO 230-4 figures of every run, location errors of the rotary axes and squareness");
    c->add_option("--machine", o->machine, "machine description XML")->required()->check(CLI::ExistingFile);
    c->add_option("--plan", o->plan, "plan with <dbb5> runs")->required()->check(CLI::ExistingFile);
    c->add_option("--traces", o->traces, "folder of trace CSVs, one <run>.csv per run")->required()->check(CLI::ExistingDirectory);
    c->add_option("--out", o->out, "deviation CSV to write (omit for the ISO 230-4 table only)");
    c->add_option("--iso-out", o->isoOut, "CSV of the ISO 230-4 figures per run");
    c->add_flag("--lsq", o->lsq, "least-squares equivalent on the raw samples instead of the paper's formulas");
    c->add_option("--refine", o->refine, "Gauss-Newton steps on the formula readings (0 = plain formulas)")->capture_default_str();
    c->add_option("--outer", o->outer, "tilting (outer) rotary axis (default: the first rotary axis of the workpiece chain)");
    c->add_option("--inner", o->inner, "rotary table (inner) axis (default: the second)");
    c->add_option("--truth", o->truth, "deviation CSV to compare with")->check(CLI::ExistingFile);
    c->callback([o] { run(*o); });
});

}  // namespace
}  // namespace cnccomp::cli
