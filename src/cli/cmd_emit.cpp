// cnccomp emit: controller compensation files from a deviation set, through one of the registered backends.
#include <chrono>
#include <ctime>
#include <filesystem>
#include <ostream>

#include <fmt/format.h>

#include "cli/command.hpp"
#include "cnccomp/error.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "cnccomp/io/output_set.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "cnccomp/io/text_util.hpp"
#include "controllers/backend.hpp"
#include "cnccomp/verify.hpp"
#include "controllers/common/evaluate.hpp"
#include "controllers/common/header.hpp"

namespace cnccomp::cli {
namespace {

struct Options {
    std::string controller, machine, deviations, out, date, plan;
};

/// What the files just written leave on the identified machine: `cnccomp verify` with the plan's test programs through
/// the backend's apply model, or (without a plan) the tool-tip error over the travel.
/// The files correct some deviations and leave others; where those partly cancelled, correcting only some makes the
/// machine worse. Said loudly: loading such files is a step back.
void warnIfWorse(bool spanWorse, bool volumetricWorse) {
    if (!spanWorse && !volumetricWorse) return;
    fmt::print("WARNING: on this machine these files leave MORE error than no compensation ({}): the deviations they cannot "
               "hold (NOT compensated above) partly cancelled those they correct. Consider corrected programs (cnccomp "
               "correct) or a controller whose files hold the rest.\n",
               spanWorse && volumetricWorse ? "ball-bar span and volumetric error" : spanWorse ? "ball-bar span" : "volumetric error");
}

void predict(const controllers::Backend& b, const MachineModel& m, const DeviationSet& d, const controllers::EmitResult& r,
             const Options& o) {
    try {
        std::shared_ptr<const controllers::AppliedCompensation> model(b.apply(m, r.files));
        if (!model) return;
        if (!o.plan.empty()) {
            const MeasurementPlan plan = readPlanXml(o.plan);
            VerifyCompensation c;
            c.kind = VerifyCompensation::Kind::ControllerFiles;
            c.backend = std::string(b.name());
            c.description = fmt::format("{} files just written", b.name());
            c.model = model;
            c.notCompensated = r.notCompensated;
            const VerifyResult v = verify(m, plan, d, "identified machine", c);
            fmt::print("predicted residual on the identified machine (cnccomp verify, {}): largest span {:.3f} um (before {:.3f} um); "
                       "volumetric max {:.3f} -> {:.3f} um\n",
                       std::filesystem::path(o.plan).filename().string(), v.residual / kUm, v.residualBefore / kUm,
                       v.volumetric.maxBefore / kUm, v.volumetric.maxAfter / kUm);
            warnIfWorse(v.residual > v.residualBefore, v.volumetric.maxAfter > v.volumetric.maxBefore);
            return;
        }
        const auto f = controllers::evaluateCompensation(m, d, *model, controllers::workspaceSamples(m, 5), 0.0);
        fmt::print("predicted tool-tip error on the identified machine over the travel ({} poses, tool length 0; give --plan for "
                   "the ball-bar residual): max {:.3f} -> {:.3f} um, RMS {:.3f} -> {:.3f} um\n",
                   f.points, f.maxBefore / kUm, f.maxAfter / kUm, f.rmsBefore / kUm, f.rmsAfter / kUm);
        warnIfWorse(false, f.maxAfter > f.maxBefore);
    } catch (const std::exception& e) {
        fmt::print("predicted residual: not available ({})\n", e.what());
    }
}

std::string today() {
    const std::time_t t = std::time(nullptr);
    std::tm tm{};
    gmtime_r(&t, &tm);
    return fmt::format("{:04}-{:02}-{:02}", tm.tm_year + 1900, tm.tm_mon + 1, tm.tm_mday);
}

void run(const Options& o) {
    const controllers::Backend& b = controllers::backend(o.controller);
    const MachineModel m = readMachineXml(o.machine);
    const DeviationSet d = readDeviationCsv(o.deviations, m);
    const std::string date = o.date.empty() ? today() : o.date;
    const controllers::EmitRequest req{m, d, std::filesystem::path(o.deviations).filename().string(), date};
    const controllers::EmitResult r = b.emit(req);
    // All or none (io/output_set.hpp): a full disk or a read-only folder leaves no file and no new folder.
    OutputSet out({o.machine, o.deviations, o.plan});
    out.makeFolder(o.out);
    for (const controllers::OutputFile& f : r.files) out.add(OutputSet::fileIn(o.out, f.name, o.controller), f.content);
    out.commit();
    fmt::print("{} compensation for '{}' from {} ({} files in {})\n", b.name(), m.name, o.deviations, r.files.size(), o.out);
    for (const controllers::OutputFile& f : r.files) fmt::print("  {}\n", f.name);
    fmt::print("{}", controllers::formatCoverage(r));
    predict(b, m, d, r, o);
}

const RegisterCommand reg([](CLI::App& app) {
    auto o = std::make_shared<Options>();
    std::string known;
    for (const controllers::Backend* b : controllers::backends()) known += fmt::format("\n  {:<16} {}", b->name(), b->description());
    auto* c = app.add_subcommand("emit", "Write compensation files for a controller; lists what is and is NOT compensated."
                                         "\nControllers:" + known);
    // What no vendor document confirmed ([G] in the files), per backend: the user checks it on the control first.
    std::string checks = "Check on the control before loading (conventions no vendor document confirmed, [G] in the files):";
    for (const controllers::Backend* b : controllers::backends()) {
        const auto list = b->checks();
        if (list.empty()) continue;
        checks += fmt::format("\n  {}:", b->name());
        for (const std::string& item : list) checks += fmt::format("\n    - {}", item);
    }
    c->footer(checks);
    c->add_option("--controller", o->controller, "controller backend (see the list above)")->required();
    c->add_option("--machine", o->machine, "machine description XML")->required()->check(CLI::ExistingFile);
    c->add_option("--deviations", o->deviations, "deviation set CSV")->required()->check(CLI::ExistingFile);
    c->add_option("--out", o->out, "output folder (created if missing)")->required();
    c->add_option("--date", o->date, "date for the header comments (default: today, UTC)");
    c->add_option("--plan", o->plan, "measurement plan XML: print the predicted ball-bar residual of the files on the identified "
                                     "machine (as cnccomp verify)")
        ->check(CLI::ExistingFile);
    c->callback([o] { run(*o); });
});

}  // namespace
}  // namespace cnccomp::cli
