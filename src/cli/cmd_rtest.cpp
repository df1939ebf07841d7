// cnccomp rtest: R-test evaluations — seed 001 (POPPE of A and C and the three squareness errors from circle, line
// and ellipse fits; volumetric error along an XYZAC run) and seed 004 (six errors of each rotary axis over angle),
// each by the paper's formulas or their least-squares equivalent (--lsq).
#include <algorithm>
#include <cmath>
#include <ostream>

#include <fmt/format.h>

#include "cli/command.hpp"
#include "cli/print.hpp"
#include "cnccomp/error.hpp"
#include "cnccomp/identification/lsq.hpp"
#include "cnccomp/identification/rtest_observation.hpp"
#include "cnccomp/identification/seed001_rtest.hpp"
#include "cnccomp/identification/seed004_cradle.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "cnccomp/io/rtest_csv.hpp"
#include "cnccomp/io/text_util.hpp"

namespace cnccomp::cli {
namespace {

struct Options {
    std::string machine, plan, traces, out, truth, method = "seed001", outer = "A", inner = "C";
    std::string volumetric, volumetricOut;
    bool lsq = false;
    int refine = 4;
};

/// Largest |value| (and |value − truth|) of every component table of the two axes.
void printTables(const DeviationSet& d, const DeviationSet* truth, const std::vector<std::string>& axes) {
    const MachineModel& m = d.machine();
    fmt::print("{:<6} {:<8} {:>5} {:>12} {:>12}  {}\n", "table", "alias", "nodes", "max |value|", truth ? "max |diff|" : "", "unit");
    for (const std::string& ax : axes)
        for (const char* c : {"EX", "EY", "EZ", "EA", "EB", "EC"}) {
            const int i = m.deviationIndex(c + ax);
            if (i < 0) continue;
            const DeviationDef& def = m.deviations[static_cast<size_t>(i)];
            const double s = def.isAngle() ? kArcsec : kUm;
            double vmax = 0, dmax = 0;
            for (int k = 0; k < def.size(); ++k) {
                vmax = std::max(vmax, std::abs(d.values[def.offset + k]) / s);
                if (truth) dmax = std::max(dmax, std::abs(d.values[def.offset + k] - truth->values[def.offset + k]) / s);
            }
            fmt::print("{:<6} {:<8} {:>5} {:12.4f} {:>12}  {}\n", def.name, def.alias, def.size(), vmax,
                       truth ? fmt::format("{:.4f}", dmax) : "", def.isAngle() ? "arcsec" : "um");
        }
}

void run(const Options& o) {
    const MachineModel m = readMachineXml(o.machine);
    refuseToOverwrite(o.out, {o.machine, o.plan, o.truth});
    if (!o.volumetricOut.empty()) refuseToOverwrite(o.volumetricOut, {o.machine, o.plan, o.truth, o.out});
    const MeasurementPlan plan = readPlanXml(o.plan);
    if (plan.rtestRuns.empty()) throw ModelError(fmt::format("plan '{}' has no <rtest> runs", o.plan));
    const std::vector<RtestTrace> traces = readRtestTraces(o.traces, m, plan.rtestRuns);
    const std::optional<DeviationSet> truth =
        o.truth.empty() ? std::nullopt : std::optional<DeviationSet>(readDeviationCsv(o.truth, m));
    const DeviationSet* t = truth ? &*truth : nullptr;
    DeviationSet d(m);
    if (o.method == "seed001") {
        if (o.lsq) {
            IdentifyOptions io;
            for (const std::string& n : {std::string("EC0Y"), std::string("EB0Z"), std::string("EA0Z"), "EY0" + o.outer,
                                         "EZ0" + o.outer, "EB0" + o.outer, "EC0" + o.outer, "EX0" + o.inner,
                                         "EY0" + o.inner, "EA0" + o.inner, "EB0" + o.inner})
                io.deviations.push_back(d.require(n));
            std::sort(io.deviations.begin(), io.deviations.end());
            const IdentificationResult r = identify(m, rtestObservations(m, plan.rtestRuns, traces), io);
            d = r.deviations;
            fmt::print("seed 001, least squares on {} displacement components: rank {} of {}, {}\n", r.report.observations,
                       r.report.rank, r.report.unknowns, r.report.termination);
            for (const std::string& w : r.report.warnings) fmt::print("warning: {}\n", w);
        } else {
            const Seed001Result r = seed001Formulas(m, plan.rtestRuns, traces, {o.outer, o.inner, o.refine});
            d = r.deviations;
            fmt::print("seed 001 fits: {} circle centre ({:.4f}, {:.4f}, {:.4f}) mm r = {:.4f} mm; {} circle centre "
                       "({:.4f}, {:.4f}, {:.4f}) mm r = {:.4f} mm\n",
                       o.outer, r.outerCircle.center.x(), r.outerCircle.center.y(), r.outerCircle.center.z(),
                       r.outerCircle.radius, o.inner, r.innerCircle.center.x(), r.innerCircle.center.y(),
                       r.innerCircle.center.z(), r.innerCircle.radius);
            fmt::print("eq. (2): C_XY = {:.3f} um/m, C_YZ = {:.3f} um/m, C_ZX = {:.3f} um/m (A tilted ±{:g} deg); "
                       "{} refinement steps on the exact model\n",
                       r.cXY * 1e6, r.cYZ * 1e6, r.cZX * 1e6, r.phiDeg, r.refine);
        }
        printDeviations(d, t);
    } else if (o.method == "seed004") {
        if (o.lsq) {
            const CradleLsq r = cradleLeastSquares(m, o.outer, o.inner, plan.rtestRuns, traces);
            d = r.deviations;
            fmt::print("seed 004, least squares: rank {} of {} ({} unobservable directions: the constant transform "
                       "between the {} and {} frames, fixed by the gauge {} errors = 0 at {} = 0), {}\n",
                       r.report.rank, r.report.unknowns, r.report.unobservable.size(), o.outer, o.inner, o.inner,
                       o.inner, r.report.termination);
        } else {
            std::vector<AxisErrors> per;
            d = seed004Formulas(m, o.outer, o.inner, plan.rtestRuns, traces, &per);
            for (const AxisErrors& a : per)
                fmt::print("seed 004 eq. (1)-(7): axis {} at {} angles, worst per-angle fit residual {:.5f} um\n", a.axis,
                           a.samples.size(),
                           std::max_element(a.samples.begin(), a.samples.end(), [](auto& x, auto& y) { return x.rms < y.rms; })->rms / kUm);
        }
        printTables(d, t, {o.outer, o.inner});
    } else {
        throw ModelError(fmt::format("unknown --method '{}' (seed001, seed004)", o.method));
    }
    writeDeviationCsv(o.out, d);
    if (!o.volumetric.empty()) {
        const auto it = std::find_if(plan.rtestRuns.begin(), plan.rtestRuns.end(), [&](auto& r) { return r.name == o.volumetric; });
        if (it == plan.rtestRuns.end()) throw ModelError(fmt::format("plan has no R-test run '{}'", o.volumetric));
        const size_t i = static_cast<size_t>(it - plan.rtestRuns.begin());
        const VolumetricAlongRun v = seed001Volumetric(m, d, *it, traces[i]);
        fmt::print("volumetric error along '{}' (section 3.2): measured RMS {:.4f} um, model RMS residual {:.4f} um, "
                   "max {:.4f} um\n",
                   o.volumetric, v.rmsMeasured / kUm, v.rmsResidual / kUm, v.maxResidual / kUm);
        if (!o.volumetricOut.empty())
            writeFileAtomically(o.volumetricOut, [&](std::ostream& out) {
                out << "pose,meas_dx_um,meas_dy_um,meas_dz_um,calc_dx_um,calc_dy_um,calc_dz_um,delta_um\n";
                for (size_t k = 0; k < v.measured.size(); ++k) {
                    const Vec3 a = v.measured[k] / kUm, b = v.predicted[k] / kUm;
                    out << fmt::format("{},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f}\n", k + 1, a.x(), a.y(), a.z(),
                                       b.x(), b.y(), b.z(), (a - b).norm());
                }
            });
    }
    fmt::print("-> {}\n", o.out);
}

const RegisterCommand reg([](CLI::App& app) {
    auto o = std::make_shared<Options>();
    auto* c = app.add_subcommand("rtest", "R-test evaluation: seed 001 (POPPE + squareness) or seed 004 (errors over angle)");
    c->add_option("--machine", o->machine, "machine description XML")->required()->check(CLI::ExistingFile);
    c->add_option("--plan", o->plan, "plan with <rtest> runs")->required()->check(CLI::ExistingFile);
    c->add_option("--traces", o->traces, "folder of R-test CSVs, one <run>.csv per run")->required()->check(CLI::ExistingDirectory);
    c->add_option("--out", o->out, "deviation CSV to write")->required();
    c->add_option("--method", o->method, "seed001 (POPPE and squareness) or seed004 (component tables)")->capture_default_str();
    c->add_flag("--lsq", o->lsq, "least-squares equivalent on the exact model instead of the paper's formulas");
    c->add_option("--refine", o->refine, "seed001: Gauss-Newton steps on the fit readings (0 = plain formulas)")->capture_default_str();
    c->add_option("--outer", o->outer, "tilting (outer) rotary axis")->capture_default_str();
    c->add_option("--inner", o->inner, "rotary table (inner) axis")->capture_default_str();
    c->add_option("--truth", o->truth, "deviation CSV to compare with")->check(CLI::ExistingFile);
    c->add_option("--volumetric", o->volumetric, "run along which to compare measured and modelled displacement (section 3.2)");
    c->add_option("--volumetric-out", o->volumetricOut, "CSV of that comparison");
    c->callback([o] { run(*o); });
});

}  // namespace
}  // namespace cnccomp::cli
