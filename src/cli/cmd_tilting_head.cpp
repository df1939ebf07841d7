// cnccomp tilting-head: seed 002, the errors of a tilting head B from absolute ball-bar runs in Y, X and Z patterns
// with two tool lengths — the paper's eq. (7), (9), (16), (21), or their least-squares equivalent (--lsq).
#include <ostream>

#include <fmt/format.h>

#include "cli/command.hpp"
#include "cli/print.hpp"
#include "cnccomp/error.hpp"
#include "cnccomp/identification/seed002_tilting_head.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "cnccomp/io/text_util.hpp"
#include "cnccomp/io/trace_csv.hpp"

namespace cnccomp::cli {
namespace {

struct Options {
    std::string machine, plan, traces, out, anglesOut, truth;
    bool lsq = false;
};

/// Per-angle rows of the head's component errors, evaluated from a deviation set at the given angles.
std::vector<TiltingHeadAngle> rowsOf(const DeviationSet& d, const std::string& head, const std::vector<double>& anglesDeg) {
    const MachineModel& m = d.machine();
    std::vector<TiltingHeadAngle> rows;
    for (double a : anglesDeg) {
        TiltingHeadAngle h;
        h.angleDeg = a;
        double* out[] = {&h.dx, &h.dy, &h.dz, &h.ex, &h.ey};
        const char* c[] = {"EX", "EY", "EZ", "EA", "EB"};
        for (int i = 0; i < 5; ++i) {
            const DeviationDef& def = m.deviations[static_cast<size_t>(d.require(c[i] + head))];
            *out[i] = def.basis.evaluate(a * kDeg, d.values.data() + def.offset, false);
        }
        rows.push_back(h);
    }
    return rows;
}

void run(const Options& o) {
    const MachineModel m = readMachineXml(o.machine);
    refuseToOverwrite(o.out, {o.machine, o.plan, o.truth});
    if (!o.anglesOut.empty()) refuseToOverwrite(o.anglesOut, {o.machine, o.plan, o.truth, o.out});
    const MeasurementPlan plan = readPlanXml(o.plan);
    if (plan.absoluteRuns.empty()) throw ModelError(fmt::format("plan '{}' has no <absolute-run> (seed 002 patterns)", o.plan));
    const std::vector<BallbarTrace> traces = readRunTraces(o.traces, plan.absoluteRuns);
    const std::optional<DeviationSet> truth =
        o.truth.empty() ? std::nullopt : std::optional<DeviationSet>(readDeviationCsv(o.truth, m));
    const TiltingHeadResult f = tiltingHeadFormulas(plan.absoluteRuns, traces);
    std::vector<double> angles;
    for (const TiltingHeadAngle& h : f.angles) angles.push_back(h.angleDeg);
    DeviationSet d(m);
    std::vector<TiltingHeadAngle> rows;
    if (o.lsq) {
        const TiltingHeadLsq r = tiltingHeadLeastSquares(m, plan.absoluteRuns, traces);
        d = r.deviations;
        rows = rowsOf(d, f.headAxis, angles);
        fmt::print("seed 002, least squares on {} samples: cost {:.3e} -> {:.3e} um², rank {} of {}, {}\n",
                   r.engine.report.observations, r.engine.report.costBefore, r.engine.report.costAfter,
                   r.engine.report.rank, r.engine.report.unknowns, r.engine.report.termination);
        fmt::print("component errors split into εxB, εBz and εx(B) with the gauge of eq. (9)\n");
        for (const std::string& w : r.engine.report.warnings) fmt::print("warning: {}\n", w);
    } else {
        d = tiltingHeadDeviations(m, f);
        rows = f.angles;
        fmt::print("seed 002, eq. (7), (9), (16), (21) with L1 = {:g} mm, L2 = {:g} mm\n", f.L1, f.L2);
    }
    writeDeviationCsv(o.out, d);
    fmt::print("{:>8} {:>10} {:>10} {:>10} {:>12} {:>12}\n", "B deg", "dx(B) um", "dy(B) um", "dz(B) um", "ex(B) arcsec",
               "ey(B) arcsec");
    for (const TiltingHeadAngle& h : rows)
        fmt::print("{:8.2f} {:10.4f} {:10.4f} {:10.4f} {:12.4f} {:12.4f}\n", h.angleDeg, h.dx / kUm, h.dy / kUm, h.dz / kUm,
                   h.ex / kArcsec, h.ey / kArcsec);
    printDeviations(d, truth ? &*truth : nullptr);
    if (!o.anglesOut.empty())
        writeFileAtomically(o.anglesOut, [&](std::ostream& out) {
            out << "B_deg,dx_um,dy_um,dz_um,ex_arcsec,ey_arcsec\n";
            for (const TiltingHeadAngle& h : rows)
                out << fmt::format("{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f}\n", h.angleDeg, h.dx / kUm, h.dy / kUm,
                                   h.dz / kUm, h.ex / kArcsec, h.ey / kArcsec);
        });
    fmt::print("-> {}{}\n", o.out, o.anglesOut.empty() ? "" : ", " + o.anglesOut);
}

const RegisterCommand reg([](CLI::App& app) {
    auto o = std::make_shared<Options>();
    auto* c = app.add_subcommand("tilting-head",
                                 "Seed 002: errors of a tilting head B from ball-bar Y/X/Z patterns with two tool lengths");
    c->add_option("--machine", o->machine, "machine description XML")->required()->check(CLI::ExistingFile);
    c->add_option("--plan", o->plan, "plan with six <absolute-run> (B-Y, B-X, B-Z at two RB)")->required()->check(CLI::ExistingFile);
    c->add_option("--traces", o->traces, "folder of trace CSVs, one <run>.csv per run")->required()->check(CLI::ExistingDirectory);
    c->add_option("--out", o->out, "deviation CSV to write (EC0B, EA0B and the component tables of B)")->required();
    c->add_flag("--lsq", o->lsq, "least-squares equivalent on the exact model instead of the paper's formulas");
    c->add_option("--angles-out", o->anglesOut, "CSV of the five errors at every measured angle");
    c->add_option("--truth", o->truth, "deviation CSV to compare with")->check(CLI::ExistingFile);
    c->callback([o] { run(*o); });
});

}  // namespace
}  // namespace cnccomp::cli
