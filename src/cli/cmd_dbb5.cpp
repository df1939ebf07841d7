// cnccomp dbb5: DBB5 ball-bar runs (Ibaraki et al.) — ISO 230-4 circularity and mean radial error of every DBB5 run, and the location errors of
// the rotary axes and squareness of the linear axes by the paper's formulas or their least-squares equivalent (--lsq).
#include <algorithm>
#include <filesystem>
#include <ostream>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "cli/command.hpp"
#include "cli/print.hpp"
#include "cnccomp/error.hpp"
#include "cnccomp/identification/dbb5_observation.hpp"
#include "cnccomp/identification/lsq.hpp"
#include "cnccomp/identification/dbb5_component_errors.hpp"
#include "cnccomp/identification/dbb5_cone_frustum.hpp"
#include "cnccomp/identification/dbb5_location_errors.hpp"
#include "cnccomp/identification/dbb5_xyc_test.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "cnccomp/io/text_util.hpp"
#include "cnccomp/io/trace_csv.hpp"

namespace cnccomp::cli {
namespace {

struct Options {
    std::string machine, plan, traces, out, isoOut, truth, outer, inner, profileOut;
    bool lsq = false, components = false;
    int refine = 4;
};

void run(const Options& o) {
    const MachineModel m = readMachineXml(o.machine);
    if (!o.out.empty()) refuseToOverwrite(o.out, {o.machine, o.plan, o.truth});
    if (!o.isoOut.empty()) refuseToOverwrite(o.isoOut, {o.machine, o.plan, o.truth, o.out});
    if (!o.profileOut.empty()) refuseToOverwrite(o.profileOut, {o.machine, o.plan, o.truth, o.out, o.isoOut});
    if (!o.profileOut.empty() && !o.components) throw ModelError("--profile-out needs --components");
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
    if (o.components) {
        const std::string inner = dbb5TableAxes(m, lo).second;
        const Dbb5ComponentProfile p = dbb5ComponentProfile(m, plan.dbb5Runs, traces, d, inner);
        d = dbb5ComponentTables(m, p, d);
        fmt::print("component errors of {} from {} (bed frame, relative to the average line; tilts: {}, axial: {}) "
                   "-> the model's tables\n",
                   inner, fmt::join(p.runs, ", "), p.tilts ? "yes" : "no", p.axial ? "yes" : "no");
        if (!o.profileOut.empty())
            writeFileAtomically(o.profileOut, [&](std::ostream& out) {
                out << "angle_deg,dx_um,dy_um,dz_um,ex_arcsec,ey_arcsec,ez_arcsec\n";
                for (size_t i = 0; i < p.angleDeg.size(); ++i)
                    out << fmt::format("{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f}\n", p.angleDeg[i],
                                       p.translation[i].x() / kUm, p.translation[i].y() / kUm, p.translation[i].z() / kUm,
                                       p.tilt[i].x() / kArcsec, p.tilt[i].y() / kArcsec, p.tilt[i].z() / kArcsec);
            });
    }
    for (size_t i = 0; i < plan.dbb5Runs.size(); ++i) {
        const Dbb5Run& r = plan.dbb5Runs[i];
        if (isDbb5XycTest(m, r)) {
            const Dbb5XycResult x = evaluateDbb5XycTest(m, r, traces[i]);
            fmt::print("XYC test {}: centre offset ({:.4f}, {:.4f}) um at R = {:g} mm -> {} {:.4f} arcsec, {} {:.4f} arcsec "
                       "(eq. (4)-(5), relative to the plane of motion)\n",
                       r.name, x.centre[0] / kUm, x.centre[1] / kUm, x.radius, fmt::format("E{}0{}", "ABC"[x.second], r.axis),
                       x.rotation[x.second] / kArcsec, fmt::format("E{}0{}", "ABC"[x.first], r.axis),
                       x.rotation[x.first] / kArcsec);
        } else if (r.kind == Dbb5Run::Kind::ConeFrustum) {
            const Dbb5ConeEvaluation c = evaluateDbb5ConeRun(m, r, traces[i], &d);
            fmt::print("cone frustum {}: circularity {:.4f} um; measured - predicted by the identified errors: rms {:.4f} "
                       "um, max {:.4f} um\n",
                       r.name, c.iso.circularity / kUm, c.rmsDifference / kUm, c.maxDifference / kUm);
        }
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
    c->add_flag("--components", o->components,
                "also the component errors (error motions) of the rotary table axis from its on-axis runs, as tables");
    c->add_option("--profile-out", o->profileOut, "CSV of the component profiles over angle (bed frame, um / arcsec)");
    c->add_option("--truth", o->truth, "deviation CSV to compare with")->check(CLI::ExistingFile);
    c->callback([o] { run(*o); });
});

}  // namespace
}  // namespace cnccomp::cli
