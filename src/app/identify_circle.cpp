#include "app/identify_circle.hpp"

#include <cmath>

#include <fmt/format.h>

#include "cnccomp/error.hpp"

namespace cnccomp::cli {

namespace {

std::string cell(double v, int width, int prec) {
    return std::isfinite(v) ? fmt::format("{:{}.{}f}", v, width, prec) : fmt::format("{:>{}}", "-", width);
}

std::string directions(const std::vector<int>& d) {
    std::string o;
    for (int x : d) o += std::string(o.empty() ? "" : " then ") + (x > 0 ? "CCW" : "CW");
    return o;
}

std::string orDash(const std::string& s) { return s.empty() ? "-" : s; }

}  // namespace

IdentifyOutcome identifyLinearCircles(const IdentifyRequest& r) {
    if (r.formulas)
        throw ModelError("the circles of the linear axes have no paper's formulas here: their diagnostics are least-squares "
                         "parameters of the exact model (leave --method at least-squares)");
    if (!r.params.empty() || !r.bounds.empty() || !r.start.empty() || r.monteCarlo > 0 || r.solver != "lm")
        throw ModelError("--params, --bounds, --start, --monte-carlo and --solver do not apply to the circles of the linear "
                         "axes: every diagnostic of the model is estimated, Gauss-Newton on the exact model");
    if (!r.eccentricities.empty()) throw ModelError("--eccentricities is for the ball-bar formulas only; this plan is 'circle'");
    if (r.traces.empty()) throw ModelError("give the measured runs with --traces DIR (one <run>.csv per <circle> of the plan)");
    if (!r.outer.empty() || !r.inner.empty() || !r.volumetricRun.empty() || r.components)
        throw ModelError("--outer, --inner, --volumetric and --components belong to rotary-axis plans, not to the circles of "
                         "the linear axes");
    LinearCircleSettings settings;
    settings.rankTolerance = r.rankTolerance;
    settings.maxIterations = r.maxIterations;
    const MachineModel& m = *r.machine;
    LinearCircleIdentification id = identifyLinearCircleRuns(m, r.plan->circleRuns, r.traces, settings);
    IdentifyOutcome out{id.deviations, std::nullopt, {}, "", std::nullopt, std::nullopt, std::nullopt};
    int samples = 0;
    for (const LinearCircleRunResult& run : id.runs) samples += run.fit.observations;
    std::string written;
    for (const LinearCircleDeviation& d : id.written) written += fmt::format("{}{}", written.empty() ? "" : ", ", d.name);
    for (const LinearCircleReversal& v : id.reversals) written += fmt::format("{}B{}", written.empty() ? "" : ", ", v.axis);
    out.summary = fmt::format("identified the diagnostics of {} circle(s) of the linear axes of '{}' (ISO 230-4 ball bar, "
                              "least squares on the exact circle model, {} samples); deviation set: {}",
                              id.runs.size(), m.name, samples, written.empty() ? "nothing written" : written);
    out.circles = std::move(id);
    return out;
}

void printLinearCircles(const LinearCircleIdentification& id) {
    for (const LinearCircleRunResult& r : id.runs) {
        const LinearCircleConditions& c = r.conditions;
        fmt::print("\nrun '{}': circle {}, centre ({:g}, {:g}, {:g}) mm, radius {:g} mm, data arc {:g} deg from {:g} deg, "
                   "feed {:g} mm/min{}, {}, overshoot {:g} deg, tool length {:g} mm\n",
                   r.run, linearPlaneName(c.plane), c.centre.x(), c.centre.y(), c.centre.z(), c.radius, c.arcDeg, c.startDeg,
                   c.feed, c.feedFromData > 0 ? fmt::format(" (data: {:.1f})", c.feedFromData) : "", directions(c.directions),
                   c.overshootDeg, c.toolLength);
        std::string samples;
        for (int n : c.samples) samples += (samples.empty() ? "" : " / ") + std::to_string(n);
        fmt::print("  samples per pass {}, spacing {:.4f} deg, {}-sampled{}; date {}, instrument {}, operator {}; file {}\n",
                   samples, c.spacingDeg, c.layout,
                   std::isfinite(c.sampleRateHz) ? fmt::format(" at {:.1f} Hz", c.sampleRateHz) : "", orDash(c.date),
                   orDash(c.instrument), orDash(c.operatorName), c.file);
        if (c.relativeLength)
            fmt::print("  relative length: the radius offset takes up the instrument's zero; F max, F min and the mean "
                       "radius are relative to it (G and H are not)\n");
        fmt::print("  ISO 230-4 (um):");
        for (size_t k = 0; k < r.iso.passes.size(); ++k) {
            const CircularTestResult& p = r.iso.passes[k];
            fmt::print(" pass {} {}: G {:.3f}, F max {:.3f}, F min {:.3f}, mean radius {:.5f} mm;", k + 1,
                       r.iso.directions[k] > 0 ? "CCW" : "CW", p.circularity / kUm, p.radialMax / kUm, p.radialMin / kUm,
                       p.meanRadius);
        }
        fmt::print(" G {:.3f}, hysteresis H {}\n", r.iso.circularDeviation / kUm,
                   std::isfinite(r.iso.hysteresis) ? fmt::format("{:.3f}", r.iso.hysteresis / kUm) : "- (one direction)");
        const LinearCircleFit& f = r.fit;
        fmt::print("  fit: {} samples, {} unknowns, rank {}, {} iteration(s), sigma {:.4f} um (rms of the trace {:.4f} um)\n",
                   f.observations, f.unknowns, f.rank, f.iterations, f.sigma, f.rmsBefore);
        fmt::print("  {:>4} {:<28} {:>10} {:>10} {:>10} {:<5} {:>10} {:>8}  {}\n", "rank", "diagnostic", "value", "low95", "high95",
                   "unit", "G alone", "share %", "model");
        int rank = 0;
        for (const LinearCircleDiagnostic& d : f.diagnostics) {
            if (!d.identified) {
                fmt::print("  {:>4} {:<28} {:>10} {:>10} {:>10} {:<5} {:>10} {:>8}  {}\n", "-", d.name, "unidentified", "-", "-",
                           d.unit, "-", "-", d.model);
                continue;
            }
            fmt::print("  {:>4} {:<28} {} {} {} {:<5} {} {}  {}\n", ++rank, d.name, cell(d.value, 10, 4), cell(d.lower95, 10, 4),
                       cell(d.upper95, 10, 4), d.unit, cell(d.circularity, 10, 4), cell(d.share, 8, 1), d.model);
        }
        for (const LinearCircleParameter& p : f.parameters)
            if (p.nuisance)
                fmt::print("  {:>4} {:<28} {} {} {} {:<5}  (nuisance)\n", "", p.name, cell(p.value, 10, 4), cell(p.lower95, 10, 4),
                           cell(p.upper95, 10, 4), p.unit);
        for (const auto& g : f.confounded) {
            std::string names;
            for (const std::string& n : g) names += (names.empty() ? "" : ", ") + n;
            fmt::print("  not identified, confounded: {}\n", names);
        }
        for (const LinearCircleCombination& cmb : f.identifiable)
            fmt::print("  identifiable combination: {} = {:.4f} +- {:.4f}\n", cmb.text, cmb.value, cmb.stddev);
        for (const std::string& w : f.warnings) fmt::print("  warning: {}\n", w);
    }
    fmt::print("\n");
    for (const LinearCircleDeviation& d : id.written) {
        std::string runs;
        for (const std::string& n : d.runs) runs += (runs.empty() ? "" : ", ") + n;
        fmt::print("deviation set: {} = {:.4f} arcsec (95 %: {:.4f} .. {:.4f}; {:.4f} um/m per arcsec; from {})\n", d.name,
                   d.value, d.lower95, d.upper95, d.perArcsec, runs);
    }
    for (const LinearCircleReversal& v : id.reversals) {
        std::string from;
        for (const std::string& n : v.from) from += (from.empty() ? "" : ", ") + n;
        fmt::print("deviation set: B{} = {:.4f} um, reversal value (ISO 230-2 B = -backlash; 95 %: {:.4f} .. {:.4f}; from {})\n",
                   v.axis, v.value, v.lower95, v.upper95, from);
    }
    for (const std::string& n : id.notes) fmt::print("note: {}\n", n);
}

}  // namespace cnccomp::cli
