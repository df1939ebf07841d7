#include "app/identify_summary.hpp"

#include <cmath>

#include <fmt/format.h>

#include "app/text_out.hpp"

namespace cnccomp::app {
using namespace cnccomp::identification;

namespace {

std::string cell(double v, double scale, int width = 10, int prec = 4) {
    return std::isfinite(v) ? fmt::format("{:{}.{}f}", v / scale, width, prec) : fmt::format("{:>{}}", "-", width);
}

void adequacyText(const TextOut& out, const Adequacy& a) {
    if (!a.tested) {
        out("model adequacy: not tested (no run has a sweep, repeated passes or a stated noise)\n");
        return;
    }
    out("model adequacy ({:.1f} %): F = {:.3g}, allowed {:.3g} -> {}\n", 100 * a.confidence, a.statistic, a.threshold,
        a.fits ? "the model fits the data" : "THE MODEL DOES NOT FIT THE DATA");
    out("{:<18} {:>10} {:>10} {:>10}  {:<24} {:>9}  {}\n", "run", "noise um", "F", "allowed", "noise from",
        "h1-6 %", "verdict");
    for (const RunAdequacy& ra : a.runs)
        out("{:<18} {:>10.4f} {:>10.3g} {:>10.3g}  {:<24} {:>9}  {}\n", ra.run, ra.noise / kUm, ra.statistic,
            ra.threshold, ra.noiseSource,
            std::isfinite(ra.harmonicShare) ? fmt::format("{:.0f}", 100 * ra.harmonicShare) : "-",
            ra.fits ? "fits" : "DOES NOT FIT");
    if (!a.fits) out("intervals: {}\n", a.inflationRule);
}

std::string plainCell(double v, int width, int prec) {
    return std::isfinite(v) ? fmt::format("{:{}.{}f}", v, width, prec) : fmt::format("{:>{}}", "-", width);
}

std::string directions(const std::vector<int>& d) {
    std::string o;
    for (int x : d) o += std::string(o.empty() ? "" : " then ") + (x > 0 ? "CCW" : "CW");
    return o;
}

std::string orDash(const std::string& s) { return s.empty() ? "-" : s; }

}  // namespace

std::string IdentificationSummary::resultReport() const {
    std::string text;
    if (report) text += formatReport(*report);
    if (circles) text += formatLinearCircles(*circles);
    return text;
}

std::string IdentificationSummary::fullReport() const { return methodTables + summary + "\n" + resultReport(); }

std::string formatReport(const IdentificationReport& r) {
    std::string text;
    const TextOut out(text);
    out("{}: {} after {} iteration(s); cost {:.6g} -> {:.6g} um^2; rank {}/{}, condition number {:.4g}, "
        "sigma {} um\n",
        r.solver, r.termination, r.iterations, r.costBefore, r.costAfter, r.rank, r.unknowns,
        r.conditionNumber, std::isfinite(r.sigma) ? fmt::format("{:.4f}", r.sigma / kUm) : "-");
    const bool mc = r.monteCarloSamples > 0;
    out("{:<14} {:>12} {:>10} {:>10} {:>10}{}  {:<6}  {}\n", "ISO name", "value", "std", "low95", "high95",
        mc ? fmt::format(" {:>10} {:>10} {:>10}", "mc std", "mc low95", "mc high95") : "", "unit", "paper alias");
    for (const ParameterEstimate& p : r.parameters) {
        const double s = p.displayScale();
        const std::string alias =
            p.alias.empty() ? "" : std::isfinite(p.aliasValue) ? fmt::format("{} = {:.4f}", p.alias, p.aliasValue / s) : p.alias;
        if (!p.identified) {
            out("{:<14} {:>12} {:>10} {:>10} {:>10}  {:<6}  {}\n", p.name, "unidentified", "-", "-", "-", p.unit(),
                p.alias);
            continue;
        }
        out("{:<14} {} {} {} {}{}  {:<6}  {}\n", p.name, cell(p.value, s, 12), cell(p.stddev, s), cell(p.lower95, s),
            cell(p.upper95, s),
            mc ? fmt::format(" {} {} {}", cell(p.mcStddev, s), cell(p.mcLower95, s), cell(p.mcUpper95, s)) : "",
            p.unit(), alias);
    }
    if (!r.identifiable.empty()) {
        out("identifiable combinations of the unidentified parameters (ISO values; coefficients in mm, rad):\n");
        for (const Combination& c : r.identifiable)
            out("  {} = {} ± {} {}  (identifiable, not each term)\n", c.text,
                cell(c.value, c.angle ? kArcsec : kUm, 0), cell(c.stddev, c.angle ? kArcsec : kUm, 0),
                c.angle ? "arcsec" : "um");
    }
    if (!r.unobservable.empty()) {
        out("directions these measurements cannot see:\n");
        for (const Combination& c : r.unobservable) out("  {}\n", c.text);
    }
    out("{:<18} {:>8} {:>14} {:>14}\n", "run", "samples", "rms before um", "rms after um");
    for (const RunResidual& rr : r.runs)
        out("{:<18} {:>8} {:>14.4f} {:>14.4f}\n", rr.run, rr.samples, rr.rmsBefore / kUm, rr.rmsAfter / kUm);
    adequacyText(out, r.adequacy);
    if (!r.stages.empty()) out("fitted in two stages: {}\n", r.stages);
    for (const std::string& w : r.warnings) out("warning: {}\n", w);
    return text;
}

std::string formatLinearCircles(const LinearCircleIdentification& id) {
    std::string text;
    const TextOut out(text);
    for (const LinearCircleRunResult& r : id.runs) {
        const LinearCircleConditions& c = r.conditions;
        out("\nrun '{}': circle {}, centre ({:g}, {:g}, {:g}) mm, radius {:g} mm, data arc {:g} deg from {:g} deg, "
            "feed {:g} mm/min{}, {}, overshoot {:g} deg, tool length {:g} mm\n",
            r.run, linearPlaneName(c.plane), c.centre.x(), c.centre.y(), c.centre.z(), c.radius, c.arcDeg, c.startDeg,
            c.feed, c.feedFromData > 0 ? fmt::format(" (data: {:.1f})", c.feedFromData) : "", directions(c.directions),
            c.overshootDeg, c.toolLength);
        std::string samples;
        for (int n : c.samples) samples += (samples.empty() ? "" : " / ") + std::to_string(n);
        out("  samples per pass {}, spacing {:.4f} deg, {}-sampled{}; date {}, instrument {}, operator {}; file {}\n",
            samples, c.spacingDeg, c.layout,
            std::isfinite(c.sampleRateHz) ? fmt::format(" at {:.1f} Hz", c.sampleRateHz) : "", orDash(c.date),
            orDash(c.instrument), orDash(c.operatorName), c.file);
        if (c.relativeLength)
            out("  relative length: the radius offset takes up the instrument's zero; F max, F min and the mean "
                "radius are relative to it (G and H are not)\n");
        out("  ISO 230-4 (um):");
        for (size_t k = 0; k < r.iso.passes.size(); ++k) {
            const CircularTestResult& p = r.iso.passes[k];
            out(" pass {} {}: G {:.3f}, F max {:.3f}, F min {:.3f}, mean radius {:.5f} mm;", k + 1,
                r.iso.directions[k] > 0 ? "CCW" : "CW", p.circularity / kUm, p.radialMax / kUm, p.radialMin / kUm,
                p.meanRadius);
        }
        out(" G {:.3f}, hysteresis H {}\n", r.iso.circularDeviation / kUm,
            std::isfinite(r.iso.hysteresis) ? fmt::format("{:.3f}", r.iso.hysteresis / kUm) : "- (one direction)");
        const LinearCircleFit& f = r.fit;
        out("  fit: {} samples, {} unknowns, rank {}, {} iteration(s), sigma {:.4f} um (rms of the trace {:.4f} um)\n",
            f.observations, f.unknowns, f.rank, f.iterations, f.sigma, f.rmsBefore);
        out("  {:>4} {:<28} {:>10} {:>10} {:>10} {:<5} {:>10} {:>8}  {}\n", "rank", "diagnostic", "value", "low95", "high95",
            "unit", "G alone", "share %", "model");
        int rank = 0;
        for (const LinearCircleDiagnostic& d : f.diagnostics) {
            if (!d.identified) {
                out("  {:>4} {:<28} {:>10} {:>10} {:>10} {:<5} {:>10} {:>8}  {}\n", "-", d.name, "unidentified", "-", "-",
                    d.unit, "-", "-", d.model);
                continue;
            }
            out("  {:>4} {:<28} {} {} {} {:<5} {} {}  {}\n", ++rank, d.name, plainCell(d.value, 10, 4), plainCell(d.lower95, 10, 4),
                plainCell(d.upper95, 10, 4), d.unit, plainCell(d.circularity, 10, 4), plainCell(d.share, 8, 1), d.model);
        }
        for (const LinearCircleParameter& p : f.parameters)
            if (p.nuisance)
                out("  {:>4} {:<28} {} {} {} {:<5}  (nuisance)\n", "", p.name, plainCell(p.value, 10, 4), plainCell(p.lower95, 10, 4),
                    plainCell(p.upper95, 10, 4), p.unit);
        for (const auto& g : f.confounded) {
            std::string names;
            for (const std::string& n : g) names += (names.empty() ? "" : ", ") + n;
            out("  not identified, confounded: {}\n", names);
        }
        for (const LinearCircleCombination& cmb : f.identifiable)
            out("  identifiable combination: {} = {:.4f} +- {:.4f}\n", cmb.text, cmb.value, cmb.stddev);
        for (const std::string& w : f.warnings) out("  warning: {}\n", w);
    }
    out("\n");
    for (const LinearCircleDeviation& d : id.written) {
        std::string runs;
        for (const std::string& n : d.runs) runs += (runs.empty() ? "" : ", ") + n;
        out("deviation set: {} = {:.4f} arcsec (95 %: {:.4f} .. {:.4f}; {:.4f} um/m per arcsec; from {})\n", d.name,
            d.value, d.lower95, d.upper95, d.perArcsec, runs);
    }
    for (const LinearCircleReversal& v : id.reversals) {
        std::string from;
        for (const std::string& n : v.from) from += (from.empty() ? "" : ", ") + n;
        out("deviation set: B{} = {:.4f} um, reversal value (ISO 230-2 B = -backlash; 95 %: {:.4f} .. {:.4f}; from {})\n",
            v.axis, v.value, v.lower95, v.upper95, from);
    }
    for (const std::string& n : id.notes) out("note: {}\n", n);
    return text;
}

}  // namespace cnccomp::app
