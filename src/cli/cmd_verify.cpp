// cnccomp verify: the plan's test programs through the compensation the user will load (a deviation set, the files of
// `cnccomp emit`, or programs corrected by `cnccomp correct`) to the true or the identified machine, before and after.
// --json and --report (HTML page, its SVGs and summary) are staged together and written only when both are complete.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "cli/command.hpp"
#include "cnccomp/error.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "cnccomp/io/output_set.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "cnccomp/io/text_util.hpp"
#include "app/verify_json.hpp"
#include "app/report/html_report.hpp"
#include "app/report/verification_report.hpp"
#include "app/verify.hpp"
#include "app/verify_sources.hpp"

namespace cnccomp::cli {
using namespace cnccomp::io;
using namespace cnccomp::measurement;
namespace {

struct Options {
    std::string machine, plan, compensation, controller, truth, identified, json, dialect = "linuxcnc";
    std::string report, reportGrid, reportPlane = "XY";
    std::optional<double> maxResidualUm, maxVolumetricUm;
    int grid = 5;
};

std::string ecc(const Vec3& v) {
    std::string s;
    for (int c = 0; c < 3; ++c) s += std::isfinite(v[c]) ? fmt::format("{:8.3f}", v[c] / kUm) : fmt::format("{:>8}", "-");
    return s;
}

void print(const app::VerifyResult& r) {
    // A compensation that makes the machine worse is said first, before any figure (VerifyWorse).
    if (r.worse.any()) fmt::print("{}\n", app::worseBanner(r));
    if (!r.worse.span)  // a run that got worse while the largest span did not (VerifyWorse::runs)
        for (const std::string& w : r.worse.runs) fmt::print("WARNING: worse after compensation in run {} (span)\n", w);
    fmt::print("verification on '{}': {}\ncompensation: {}\n", r.machine, r.simulated, r.compensation);
    fmt::print("{:<22} {:<16} {:<7} {:>19} {:>19} {:>19}   {:<24}  {}\n", "run", "type", "pass", "span before/after",
               "G before/after", "F max/min after", "eccentricity before (um)", "after");
    for (const app::VerifyRun& run : r.runs)
        for (const app::VerifyPass& p : run.passes) {
            const std::string g = p.circular ? fmt::format("{:9.3f} {:9.3f}", p.isoBefore.circularity / kUm, p.isoAfter.circularity / kUm)
                                             : fmt::format("{:>19}", "-");
            const std::string f = p.circular ? fmt::format("{:9.3f} {:9.3f}", p.isoAfter.radialMax / kUm, p.isoAfter.radialMin / kUm)
                                             : fmt::format("{:>19}", "-");
            fmt::print("{:<22} {:<16} {:<7} {:9.3f} {:9.3f} {} {}   {}  {}\n", run.name, run.type, p.label, p.spanBefore / kUm,
                       p.spanAfter / kUm, g, f, p.circular ? ecc(p.eccentricityBefore) : "", p.circular ? ecc(p.eccentricityAfter) : "");
        }
    fmt::print("(um; span = max - min of dL, R-test: of a displacement component; G = ISO 230-4 circular deviation; "
               "F = radial deviation)\n");
    for (const app::VerifyRun& run : r.runs)
        for (const app::VerifyPass& p : run.passes)
            if (!p.outsideTravel.empty())
                fmt::print("warning: run '{}' {}: the compensated commands leave the travel: {}\n", run.name, p.label, p.outsideTravel);
    const app::VerifyVolumetric& v = r.volumetric;
    if (v.available)
        fmt::print("volumetric tool-tip error over the plan's workspace ({} points: {}):\n  max {:.3f} -> {:.3f} um, RMS {:.3f} -> "
                   "{:.3f} um, tool-axis tilt {:.2f} -> {:.2f} arcsec\n",
                   v.points, v.note, v.maxBefore / kUm, v.maxAfter / kUm, v.rmsBefore / kUm, v.rmsAfter / kUm,
                   v.tiltBefore / kArcsec, v.tiltAfter / kArcsec);
    else
        fmt::print("volumetric: {}\n", v.note);
    if (r.remaining.empty()) {
        fmt::print("deviations left by the compensation: none listed\n");
    } else {
        // Under its ISO name the ISO value, under the paper alias the alias' value: the numbers an engineer adjusts.
        fmt::print("deviations left by the compensation (ISO 230-1 value in the simulated machine, paper alias, reason):\n");
        for (const app::VerifyRemaining& x : r.remaining) {
            const std::string alias = x.alias.empty() ? "" : fmt::format("{} {:+.3f} {}", x.alias, x.aliasValue, x.unit);
            fmt::print("  {:<10} {:>16}  {:<20}  {}\n", x.deviation, x.valueKnown ? fmt::format("{:+.3f} {}", x.value, x.unit) : "-",
                       alias, x.reason);
        }
    }
    fmt::print("residual (largest span after compensation): {:.3f} um (before: {:.3f} um)\n", r.residual / kUm,
               r.residualBefore / kUm);
}

void run(const Options& o) {
    const MachineModel m = readMachineXml(o.machine);
    const MeasurementPlan plan = readPlanXml(o.plan);
    const std::string source = !o.compensation.empty() ? o.compensation : o.identified;
    if (source.empty()) throw InputError("--compensation", 0, "give the compensation to verify (deviation CSV or folder)");
    const auto dialect = postproc::parseDialect(o.dialect, postproc::DialectUse::Write);
    if (!dialect) throw InputError("--dialect", 0, fmt::format("unknown dialect '{}' ({})", o.dialect, postproc::dialectNames(postproc::DialectUse::Write)));
    if (o.maxResidualUm && !(*o.maxResidualUm >= 0)) throw InputError("--max-residual-um", 0, "expected a number >= 0");
    if (o.maxVolumetricUm && !(*o.maxVolumetricUm >= 0)) throw InputError("--max-volumetric-um", 0, "expected a number >= 0");
    namespace fs = std::filesystem;
    if (!o.report.empty()) {
        if (!app::report::isHtmlPath(o.report)) throw InputError(o.report, 0, "--report writes an HTML page: give R.html");
        if (!o.json.empty() && fs::path(o.json).lexically_normal() == fs::path(o.report).lexically_normal())
            throw InputError(o.report, 0, "--json and --report name the same file");
    } else if (!o.reportGrid.empty()) {
        throw InputError("--report-grid", 0, "belongs to an HTML report: give --report R.html");
    }
    app::LoadedCompensation c = app::loadCompensation(m, plan, source, o.controller);
    std::optional<DeviationSet> simulated;
    std::string simulatedName;
    if (!o.truth.empty()) {
        simulated = readDeviationCsv(o.truth, m);
        simulatedName = fmt::format("true machine ({})", fs::path(o.truth).filename().string());
    } else if (!o.identified.empty()) {
        simulated = readDeviationCsv(o.identified, m);
        simulatedName = fmt::format("identified machine ({}): predicted residual", fs::path(o.identified).filename().string());
    } else if (c.identified) {
        simulated = c.identified;
        simulatedName = fmt::format("identified machine ({}): predicted residual", fs::path(source).filename().string());
    } else {
        throw InputError("--truth", 0,
                         "the machine to simulate is missing: --truth T.csv (simulation) or --identified D.csv (the set the "
                         "compensation was made from)");
    }
    app::VerifyOptions vo;
    vo.dialect = *dialect;
    vo.volumetricPerAxis = o.grid;
    const app::VerifyResult r = app::verify(m, plan, *simulated, simulatedName, c.compensation, vo);
    // Every output is computed before any is written; a compensation folder's files are inputs too.
    std::vector<std::string> inputs{o.machine, o.plan, o.truth, o.identified, o.compensation};
    inputs.insert(inputs.end(), c.compensation.files.begin(), c.compensation.files.end());
    OutputSet staged(inputs);
    for (const std::string& out : {o.json, o.report})  // missing folders are created (and removed again on failure)
        if (!out.empty() && !fs::path(out).parent_path().empty()) staged.makeFolder(fs::path(out).parent_path().string());
    if (!o.json.empty()) staged.add(o.json, app::formatVerifyJson(r, o.maxResidualUm, o.maxVolumetricUm));
    if (!o.report.empty()) {
        app::report::VerificationReportInputs in;
        in.machineFile = o.machine;
        in.planFile = o.plan;
        in.compensationPath = source;
        in.dialect = o.dialect;
        in.gateUm = o.maxResidualUm;
        in.volumetricGateUm = o.maxVolumetricUm;
        in.compensationSet = c.identified ? &*c.identified : nullptr;
        in.map.grid = o.reportGrid;
        in.map.plane = o.reportPlane;
        const app::report::ReportData d = app::report::verificationReport(m, *simulated, c.compensation, r, in);
        app::report::stageHtmlReport(staged, o.report, d);
    }
    staged.commit();
    print(r);
    if (!o.report.empty()) fmt::print("report -> {}\n", o.report);
    // Every gate is decided and said; any failure is exit status 1. The worse gate holds whatever the options say.
    std::vector<std::string> failed;
    if (r.worse.any()) failed.push_back("verification failed: " + app::worseBanner(r));
    if (o.maxResidualUm) {
        if (r.residual / kUm > *o.maxResidualUm)
            failed.push_back(fmt::format("verification failed: residual {:.3f} um is above --max-residual-um {:g}", r.residual / kUm,
                                         *o.maxResidualUm));
        else
            fmt::print("verification passed: residual {:.3f} um <= {:g} um\n", r.residual / kUm, *o.maxResidualUm);
    }
    if (o.maxVolumetricUm) {
        // A ball bar cannot see everything (e.g. a shift of the workpiece datum): the volumetric error can.
        if (!r.volumetric.available)
            failed.push_back(fmt::format("verification failed: --max-volumetric-um needs the volumetric figure, which this "
                                         "compensation has none of ({})",
                                         r.volumetric.note));
        else if (r.volumetric.maxAfter / kUm > *o.maxVolumetricUm)
            failed.push_back(fmt::format("verification failed: volumetric tool-tip error {:.3f} um is above --max-volumetric-um {:g}",
                                         r.volumetric.maxAfter / kUm, *o.maxVolumetricUm));
        else
            fmt::print("verification passed: volumetric tool-tip error {:.3f} um <= {:g} um\n", r.volumetric.maxAfter / kUm,
                       *o.maxVolumetricUm);
    }
    if (!failed.empty()) {
        std::fflush(stdout);  // the report (banner first) before main's error lines on stderr, also through a pipe
        std::string all;
        for (const std::string& f : failed) all += (all.empty() ? "" : "\n") + f;
        throw std::runtime_error(all);
    }
}

const RegisterCommand reg([](CLI::App& app) {
    auto o = std::make_shared<Options>();
    auto* c = app.add_subcommand(
        "verify",
        "Run the plan's test programs through the compensation you will load, to the true machine (--truth) or the\n"
        "identified one, and compare the instrument readings before and after (ISO 230-4 G and F, eccentricity,\n"
        "dL span), the volumetric error over the plan's workspace, and the deviations left.\n"
        "--compensation: a deviation CSV (ideal compensation), a folder written by `cnccomp emit` (backend recognised\n"
        "from the file names, or --controller), or a folder of test programs corrected by `cnccomp correct`.\n"
        "Exit status: 0 verified (residual at or below --max-residual-um and volumetric error at or below\n"
        "--max-volumetric-um, or no gate, and the compensation does not make the machine worse); 1 a gate failed,\n"
        "or the compensation makes the machine worse than none, whatever the gates (largest span or volumetric error\n"
        "after above before by more than max(0.1 um, 1 % of before)) (report printed and --json written first; 1 also\n"
        "for an unexpected internal error);\n"
        "2 bad input (unreadable or unrecognised files, unknown names, commands outside the travel);\n"
        "105/106/109 command-line usage (invalid value, missing option, unknown option).");
    c->add_option("--machine", o->machine, "machine description XML")->required()->check(CLI::ExistingFile);
    c->add_option("--plan", o->plan, "measurement plan XML")->required()->check(CLI::ExistingFile);
    c->add_option("--compensation", o->compensation, "deviation CSV, `cnccomp emit` folder or folder of corrected test programs")
        ->check(CLI::ExistingPath);
    c->add_option("--controller", o->controller, "backend of the folder's files (default: recognised from the file names)");
    c->add_option("--truth", o->truth, "deviations of the real machine (CSV): simulate the true machine")->check(CLI::ExistingFile);
    c->add_option("--identified", o->identified,
                  "identified deviations (CSV) the compensation was made from: the machine simulated without --truth "
                  "(alone: the compensation itself, ideal)")
        ->check(CLI::ExistingFile);
    c->add_option("--max-residual-um", o->maxResidualUm, "gate: exit status 1 when the residual (largest span after) is above");
    c->add_option("--max-volumetric-um", o->maxVolumetricUm,
                  "gate: exit status 1 when the volumetric tool-tip error after compensation (max over the plan's "
                  "workspace) is above; it sees what a ball bar cannot, e.g. a shifted workpiece datum");
    c->add_option("--json", o->json, "write the result as JSON (schema cnccomp-verify/1)");
    c->add_option("--report", o->report,
                  "write an HTML page R.html: polar plots of every run before and after (CW and CCW), ISO 230-4 G, F, H, "
                  "spans, the compensation with its coverage and residual, maps before and after; each plot also as "
                  "R-polar-<run>.svg / R-map-<k>.svg, the numbers as R.summary.json");
    c->add_option("--report-grid", o->reportGrid, "HTML report: map grid as for cnccomp map (default: X, Y over the travel)");
    c->add_option("--report-plane", o->reportPlane, "HTML report: map plane as for cnccomp map --plane")->capture_default_str();
    c->add_option("--dialect", o->dialect, "dialect of the test programs generated in memory (linuxcnc, fanuc, sinumerik, heidenhain)")
        ->capture_default_str();
    c->add_option("--volumetric-grid", o->grid, "samples per axis of the volumetric grid")->capture_default_str()->check(CLI::Range(1, 20));
    c->callback([o] { run(*o); });
});

}  // namespace
}  // namespace cnccomp::cli
