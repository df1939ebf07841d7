// cnccomp emit: controller compensation files from a deviation set, through one of the registered backends.
#include <chrono>
#include <ctime>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <optional>
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
#include "app/verify.hpp"
#include "controllers/common/evaluate.hpp"
#include "controllers/common/fit.hpp"
#include "controllers/common/header.hpp"

namespace cnccomp::cli {
using namespace cnccomp::io;
using namespace cnccomp::measurement;
namespace {

struct Options {
    std::string controller, machine, deviations, out, date, plan;
    int fitGrid = 5;
    std::vector<double> fitToolLengths;
    bool copyIdentified = false;
};

/// Where the values are fitted (controllers/common/fit.hpp): the plan's workspace (the grid `cnccomp verify` takes its
/// volumetric figure over) and a grid over the machine's travel, at the tool lengths given (default 0 and 100 mm and
/// the plan's own).
controllers::common::FitWorkspace fitWorkspace(const MachineModel& m, const MeasurementPlan* plan, const Options& o) {
    if (o.fitGrid < 1 || o.fitGrid > 12) throw ModelError(fmt::format("--fit-grid {}: expected 1 to 12 samples per axis", o.fitGrid));
    for (double L : o.fitToolLengths)
        if (!std::isfinite(L) || L < 0 || L > 2000)
            throw ModelError(fmt::format("--fit-tool-lengths: {:g} is not a tool length (0 to 2000 mm)", L));
    controllers::common::FitWorkspace w;
    std::vector<double> lengths = o.fitToolLengths.empty() ? std::vector<double>{0.0, 100.0} : o.fitToolLengths;
    std::string what;
    if (plan) {
        app::VerifyOptions vo;
        vo.volumetricPerAxis = o.fitGrid;
        const app::PlanWorkspace p = app::planWorkspace(m, *plan, vo);
        w.poses = p.poses;
        if (o.fitToolLengths.empty())
            for (double L : p.toolLengths)
                if (std::find(lengths.begin(), lengths.end(), L) == lengths.end()) lengths.push_back(L);
        what = fmt::format("plan {}: {} per axis over the commands of its runs + ", std::filesystem::path(o.plan).filename().string(),
                           o.fitGrid);
    }
    const std::vector<AxisVector> travel = controllers::common::workspaceSamples(m, o.fitGrid);
    w.poses.insert(w.poses.end(), travel.begin(), travel.end());
    w.toolLengths = lengths;
    w.description = fmt::format("{}{} per axis over the travel (linear axes within +-200 mm) = {} poses, tool lengths", what,
                                o.fitGrid, w.poses.size());
    for (double L : lengths) w.description += fmt::format(" {:g}", L);
    w.description += " mm";
    return w;
}

/// What one candidate's files leave on the identified machine through the plan's test programs (cnccomp verify).
app::VerifyResult verifyFiles(const controllers::Backend& b, const MachineModel& m, const MeasurementPlan& plan, const DeviationSet& identified,
                         const controllers::EmitResult& r, const std::string& what, int volumetricPerAxis = 5) {
    app::VerifyCompensation c;
    c.kind = app::VerifyCompensation::Kind::ControllerFiles;
    c.backend = std::string(b.name());
    c.description = what;
    c.model = std::shared_ptr<const controllers::AppliedCompensation>(b.apply(m, r.files));
    c.notCompensated = r.notCompensated;
    app::VerifyOptions vo;
    vo.volumetricPerAxis = volumetricPerAxis;
    return app::verify(m, plan, identified, "identified machine", c, vo);
}

/// The files correct some deviations and leave others; where those partly cancelled, correcting only some makes the
/// machine worse. Said loudly, but only beyond the tolerance of controllers/common/fit.hpp (1 % or 0.01 um): below it the
/// difference is rounding.
void warnIfWorse(bool spanWorse, bool volumetricWorse, bool rtest) {
    if (!spanWorse && !volumetricWorse) return;
    const std::string span = rtest ? "R-test displacement" : "ball-bar span";
    fmt::print("WARNING: on this machine these files leave MORE error than no compensation ({}, beyond 1 % or 0.01 um): the "
               "deviations they cannot hold (NOT compensated above) partly cancelled those they correct. Consider corrected "
               "programs (cnccomp correct) or a controller whose files hold the rest.\n",
               spanWorse && volumetricWorse ? span + " and volumetric error" : spanWorse ? span : "volumetric error");
}

bool beyondTolerance(double after, double before) {
    return after > before + std::max(controllers::common::kFitTolerance.absolute, controllers::common::kFitTolerance.relative * before);
}

/// The three candidates side by side, and the prediction for the files written.
void predict(const controllers::Backend& b, const MachineModel& m, const DeviationSet& d, const controllers::common::FitWorkspace& w,
             const controllers::common::FitOutcome& fit, bool fitted, const controllers::EmitResult& written, const MeasurementPlan* plan,
             const Options& o) {
    try {
        struct Row {
            const char* name;
            const controllers::common::FitFigures* f;
            const DeviationSet* values;
        };
        DeviationSet zero = d;
        zero.values.setZero();
        const Row rows[] = {{"none", &fit.none, &zero}, {"identified values copied", &fit.copied, &d}, {"fitted", &fit.fitted, fit.fittedValues ? &*fit.fittedValues : &fit.written}};
        // Files holding the sampled error (the generic map) are not fitted unless the copy leaves next to nothing (then
        // the fit is the copy, "fitted"): the fitted row is not computed (fit.cpp).
        const bool sampled = fitted && !b.fitsDeviationValues() && fit.chosen != "fitted";
        bool rtest = false;
        std::vector<double> spans(3, NAN);
        if (plan) {
            for (int i = 0; i < 3; ++i) {
                if (i == 2 && (!fitted || sampled)) continue;
                const controllers::EmitRequest req{m, *rows[i].values, "prediction", "2000-01-01"};
                // The candidates' spans only (their volumetric figure is the fit's own, above): one volumetric point.
                const app::VerifyResult v = verifyFiles(b, m, *plan, d, b.emit(req), rows[i].name, 1);
                spans[static_cast<size_t>(i)] = v.residual;
                for (const app::VerifyRun& run : v.runs) rtest = rtest || run.kind == postproc::testprog::RunKind::Rtest;
            }
        }
        const std::string spanName = rtest ? "largest R-test displacement (um)" : "largest span (um)";
        fmt::print("predictions on the identified machine over the fit workspace ({}):\n", controllers::common::judgedWorkspace(m, w).description);
        fmt::print("  {:<26} {:>28}{}\n", "candidate", "tool tip max / RMS (um)", plan ? fmt::format("  {:>34}", spanName) : "");
        for (int i = 0; i < 3; ++i) {
            if (i == 2 && (!fitted || sampled)) {
                fmt::print("  {:<26} {:>28}\n", rows[i].name,
                           sampled ? "not computed (the files hold the error itself, sampled)" : "not computed (--copy-identified)");
                continue;
            }
            const std::string tip = fmt::format("{:.3f} / {:.3f}", rows[i].f->maxTip / kUm, rows[i].f->rmsTip / kUm);
            fmt::print("  {:<26} {:>28}{}\n", rows[i].name, tip, plan ? fmt::format("  {:>34.3f}", spans[static_cast<size_t>(i)] / kUm) : "");
        }
        const bool chosenFitted = fitted && fit.chosen == "fitted";
        const controllers::common::FitFigures& chosen = !fitted ? fit.copied : fit.chosen == "none" ? fit.none : fit.chosen == "identified" ? fit.copied : fit.fitted;
        fmt::print("written: {}\n", !fitted                       ? "the identified values copied (--copy-identified)"
                                     : chosenFitted                 ? (fit.heldValues < 0 ? "the fitted values (= the identified values: "
                                                                                            "the controller holds them all)"
                                                                                          : "the fitted values")
                                     : fit.chosen == "identified"   ? (sampled ? "the identified values copied"
                                                                               : "the identified values copied (the fit left more)")
                                                                    : sampled ? "zero values (the copy left more than none)"
                                                                              : "zero values (every other candidate left more than none)");
        if (plan) {
            app::VerifyResult v = verifyFiles(b, m, *plan, d, written, fmt::format("{} files just written", b.name()));
            fmt::print("predicted residual on the identified machine (cnccomp verify, {}): largest span {:.3f} um (before {:.3f} um); "
                       "volumetric max {:.3f} -> {:.3f} um\n",
                       std::filesystem::path(o.plan).filename().string(), v.residual / kUm, v.residualBefore / kUm,
                       v.volumetric.maxBefore / kUm, v.volumetric.maxAfter / kUm);
            warnIfWorse(beyondTolerance(v.residual, v.residualBefore), controllers::common::leavesMore(chosen, fit.none), rtest);
            return;
        }
        fmt::print("predicted tool-tip error on the identified machine over the travel and fit workspace ({} poses x {} tool lengths; "
                   "give --plan for the ball-bar residual): max {:.3f} -> {:.3f} um, RMS {:.3f} -> {:.3f} um\n",
                   w.poses.size(), w.toolLengths.size(), fit.none.maxTip / kUm, chosen.maxTip / kUm, fit.none.rmsTip / kUm,
                   chosen.rmsTip / kUm);
        warnIfWorse(false, controllers::common::leavesMore(chosen, fit.none), false);
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
    std::optional<MeasurementPlan> plan;
    if (!o.plan.empty()) plan = readPlanXml(o.plan);
    const controllers::common::FitWorkspace w = fitWorkspace(m, plan ? &*plan : nullptr, o);
    // The values written: fitted to what this controller holds (controllers/common/fit.hpp), or with --copy-identified
    // the identified values as they are (the files of earlier versions, byte for byte).
    controllers::common::FitOutcome fit{d, "identified", {}, {}, {}, {}, {}, -1};
    if (o.copyIdentified) {
        DeviationSet zero = d;
        zero.values.setZero();
        fit.none = controllers::common::fitFigures(b, m, d, zero, w);
        fit.copied = controllers::common::fitFigures(b, m, d, d, w);
    } else {
        fit = controllers::common::fitControllerValues(b, m, d, w);
    }
    controllers::EmitRequest req{m, fit.written, std::filesystem::path(o.deviations).filename().string(), date};
    if (!o.copyIdentified) {
        req.fitWorkspace = &w;
        req.headerNotes = fit.notes;
    }
    controllers::EmitResult r = b.emit(req);
    for (controllers::Coverage& c : controllers::common::reversalsNotHeld(req, r.compensated))
        if (std::none_of(r.notCompensated.begin(), r.notCompensated.end(),
                         [&](const controllers::Coverage& n) { return n.deviation == c.deviation; }))
            r.notCompensated.push_back(std::move(c));
    // All or none (io/output_set.hpp): a full disk or a read-only folder leaves no file and no new folder.
    OutputSet out({o.machine, o.deviations, o.plan});
    out.makeFolder(o.out);
    for (const controllers::OutputFile& f : r.files) out.add(OutputSet::fileIn(o.out, f.name, o.controller), f.content);
    out.commit();
    fmt::print("{} compensation for '{}' from {} ({} files in {})\n", b.name(), m.name, o.deviations, r.files.size(), o.out);
    for (const controllers::OutputFile& f : r.files) fmt::print("  {}\n", f.name);
    for (const std::string& l : r.summary) fmt::print("{}\n", l);
    fmt::print("{}", controllers::common::formatCoverage(r));
    predict(b, m, d, w, fit, !o.copyIdentified, r, plan ? &*plan : nullptr, o);
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
    c->add_option("--fit-grid", o->fitGrid, "samples per axis of the fit workspace's grids (over the plan's commands and over the "
                                            "travel; default 5)");
    c->add_option("--fit-tool-lengths", o->fitToolLengths, "tool lengths (mm) of the fit workspace, e.g. 0,100,360 (default 0 "
                                                          "and 100 and the plan's own)")
        ->delimiter(',');
    c->add_flag("--copy-identified", o->copyIdentified, "write the identified values as they are (no fit to what the controller "
                                                        "holds): the files of earlier versions");
    c->callback([o] { run(*o); });
});

}  // namespace
}  // namespace cnccomp::cli
