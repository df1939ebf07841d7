// cnccomp identify: deviations from ball-bar measurements.
#include <algorithm>

#include <fmt/format.h>

#include "cli/command.hpp"
#include "cli/print.hpp"
#include "cnccomp/closed_form.hpp"
#include "cnccomp/error.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/eccentricity_csv.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "cnccomp/io/text_util.hpp"
#include "cnccomp/io/trace_csv.hpp"

namespace cnccomp::cli {
namespace {

struct Options {
    std::string method = "closed-form";
    std::string machine, eccentricities, traces, plan, out;
    int refine = 3;
};

void run(const Options& o) {
    const MachineModel m = readMachineXml(o.machine);
    refuseToOverwrite(o.out, {o.machine, o.eccentricities, o.plan});
    if (o.method != "closed-form") throw ModelError(fmt::format("unknown --method '{}'", o.method));
    std::vector<EccentricityRow> rows;
    if (!o.eccentricities.empty()) {
        if (!o.traces.empty()) throw ModelError("give either --eccentricities or --traces with --plan, not both");
        rows = readEccentricityCsv(o.eccentricities);
    } else {
        if (o.traces.empty() || o.plan.empty())
            throw ModelError("closed form needs --eccentricities E.csv, or --traces DIR with --plan P.xml");
        const MeasurementPlan plan = readPlanXml(o.plan);
        rows = eccentricitiesFromTraces(m, plan.runs, readRunTraces(o.traces, plan.runs));
    }
    if (o.refine < 0 || o.refine > 20) throw ModelError("--refine takes 0..20 passes");
    const DeviationSet d = identifyClosedForm(m, rows, {o.refine, 1.0});
    writeDeviationCsv(o.out, d);
    fmt::print("identified {} deviations of '{}' (closed form, seed 000 eq. (17)-(28)) -> {}\n",
               std::count(d.present.begin(), d.present.end(), 1), m.name, o.out);
    printDeviations(d, nullptr);
}

const RegisterCommand reg([](CLI::App& app) {
    auto o = std::make_shared<Options>();
    auto* c = app.add_subcommand("identify", "Identify the machine's deviations from ball-bar measurements");
    c->add_option("--method", o->method, "closed-form (seed 000 eq. (17)-(28))")->capture_default_str();
    c->add_option("--machine", o->machine, "machine description XML")->required()->check(CLI::ExistingFile);
    c->add_option("--eccentricities", o->eccentricities, "eccentricity CSV (closed form)")->check(CLI::ExistingFile);
    c->add_option("--traces", o->traces, "folder of trace CSVs, one <run>.csv per run")->check(CLI::ExistingDirectory);
    c->add_option("--plan", o->plan, "measurement plan XML")->check(CLI::ExistingFile);
    c->add_option("--out", o->out, "deviation CSV to write")->required();
    c->add_option("--refine", o->refine,
                  "closed form: defect-correction passes on the exact model (0 = the paper's formulas only)")
        ->capture_default_str();
    c->callback([o] { run(*o); });
});

}  // namespace
}  // namespace cnccomp::cli
