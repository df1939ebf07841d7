#include "app/report/linear_circle_report.hpp"

#include <cmath>

#include <fmt/format.h>

#include "app/report/report_format.hpp"

namespace cnccomp::app::report {

// Internals in a named namespace (not anonymous): the core may be compiled as unity units.
namespace linear_circle_report_detail {

std::string lcOrDash(const std::string& s) { return s.empty() ? "–" : s; }

std::string lcDirections(const std::vector<int>& d) {
    std::string o;
    for (int x : d) o += std::string(o.empty() ? "" : " then ") + (x > 0 ? "CCW" : "CW");
    return o;
}

}  // namespace linear_circle_report_detail

ReportData linearCircleReportData(const std::string& machine, const LinearCircleIdentification& id,
                                  std::vector<std::pair<std::string, std::string>> facts) {
    using namespace linear_circle_report_detail;
    ReportData d;
    d.title = fmt::format("Ball-bar circles of the linear axes (ISO 230-4): {}", machine);
    d.machine = machine;
    d.facts = std::move(facts);
    d.afterNote = "the identified diagnostics removed from the measured trace (what the machine would show with them "
                  "corrected)";
    TableSection conditions;
    conditions.title = "Test conditions";
    conditions.header = {"run", "plane", "centre (mm)", "radius mm", "data arc", "feed mm/min", "overshoot deg", "directions",
                         "samples per pass", "spacing deg", "sample rate Hz", "file layout", "date", "instrument", "operator",
                         "file"};
    TableSection perPass;
    perPass.title = "ISO 230-4 figures per pass";
    perPass.header = {"run", "pass", "samples", "circular deviation G µm", "F max µm", "F min µm", "mean radius mm"};
    for (const LinearCircleRunResult& r : id.runs) {
        const LinearCircleConditions& c = r.conditions;
        RunSection s;
        s.name = r.run;
        s.test = fmt::format("circle {}", linearPlaneName(c.plane));
        s.LB = c.radius;
        std::vector<DirectedTrace> after;
        for (size_t k = 0; k < r.passes.size(); ++k) {
            const LinearCirclePass& p = r.passes[k];
            s.passes.push_back({p.direction, p.angleDeg, p.dL, r.after[k]});
            after.push_back({p.direction, BallbarTrace{p.angleDeg, r.after[k]}});
        }
        s.before = isoFigures(r.iso);
        s.after = isoFigures(evaluateCircularRun(after, c.radius));
        s.rmsBefore = r.fit.rmsBefore * kUm;
        s.rmsAfter = r.fit.sigma * kUm;
        s.notes.push_back(fmt::format("{} {:g}° from {:g}°, R {:g} mm, F {:g} mm/min, {} ({}-sampled)",
                                      linearPlaneName(c.plane), c.arcDeg, c.startDeg, c.radius, c.feed,
                                      lcDirections(c.directions), c.layout));
        if (c.relativeLength)
            s.notes.push_back("relative length: F and the mean radius are relative to the instrument's zero (G and H are not)");
        d.runs.push_back(std::move(s));

        std::string samples;
        for (int n : c.samples) samples += (samples.empty() ? "" : " / ") + std::to_string(n);
        conditions.rows.push_back({r.run, linearPlaneName(c.plane),
                                   fmt::format("{:g} {:g} {:g}", c.centre.x(), c.centre.y(), c.centre.z()),
                                   fmt::format("{:g}", c.radius),
                                   fmt::format("{:g}° from {:g}° to {:g}°", c.arcDeg, c.startDeg, c.startDeg + c.arcDeg),
                                   c.feedFromData > 0 ? fmt::format("{:g} (data: {:.1f})", c.feed, c.feedFromData)
                                                      : fmt::format("{:g}", c.feed),
                                   fmt::format("{:g}", c.overshootDeg), lcDirections(c.directions), samples,
                                   fixed(c.spacingDeg, 4), fixed(c.sampleRateHz, 1), c.layout, lcOrDash(c.date),
                                   lcOrDash(c.instrument), lcOrDash(c.operatorName), c.file});
        for (size_t k = 0; k < r.iso.passes.size(); ++k) {
            const CircularTestResult& p = r.iso.passes[k];
            perPass.rows.push_back({r.run, fmt::format("{} ({})", k + 1, r.iso.directions[k] > 0 ? "CCW" : "CW"),
                                    std::to_string(p.samples), fixed(p.circularity / kUm, 3), fixed(p.radialMax / kUm, 3),
                                    fixed(p.radialMin / kUm, 3), fixed(p.meanRadius, 5)});
        }
    }
    d.tables.push_back(std::move(conditions));
    d.tables.push_back(std::move(perPass));
    for (const LinearCircleRunResult& r : id.runs) {
        TableSection t;
        t.title = fmt::format("Diagnostics of '{}', ranked by their share of the circularity", r.run);
        t.header = {"rank", "diagnostic", "value", "unit", "95 % low", "95 % high", "G alone µm", "share %", "model"};
        int rank = 0;
        for (const LinearCircleDiagnostic& g : r.fit.diagnostics) {
            if (!g.identified) {
                t.rows.push_back({"–", g.name, "not identified", g.unit, "–", "–", "–", "–", g.model});
                continue;
            }
            t.rows.push_back({std::to_string(++rank), g.name, fixed(g.value, 3), g.unit, fixed(g.lower95, 3),
                              fixed(g.upper95, 3), fixed(g.circularity, 3), fixed(g.share, 1), g.model});
        }
        for (const LinearCircleParameter& p : r.fit.parameters)
            if (p.nuisance)
                t.rows.push_back({"nuisance", p.name, p.identified ? fixed(p.value, 3) : "not identified", p.unit,
                                  fixed(p.lower95, 3), fixed(p.upper95, 3), "–", "–",
                                  "ISO 230-4 set-up (centring) / bar length"});
        t.notes.push_back(fmt::format("measured circular deviation G {} µm (largest of the passes); fit: {} samples, {} "
                                      "unknowns, rank {}, σ̂ {} µm. Share = G of the trace this diagnostic alone makes / "
                                      "measured G (shares do not add up to 100 %).",
                                      fixed(r.fit.measuredCircularity, 3), r.fit.observations, r.fit.unknowns, r.fit.rank,
                                      fixed(r.fit.sigma, 4)));
        for (const auto& g : r.fit.confounded) {
            std::string names;
            for (const std::string& n : g) names += (names.empty() ? "" : ", ") + n;
            t.notes.push_back("Not identified, confounded (these data cannot tell them apart): " + names);
        }
        for (const LinearCircleCombination& c : r.fit.identifiable)
            t.notes.push_back(fmt::format("Identifiable combination: {} = {} ± {}", c.text, fixed(c.value, 3), fixed(c.stddev, 3)));
        for (const std::string& w : r.fit.warnings) d.warnings.push_back(fmt::format("{}: {}", r.run, w));
        d.tables.push_back(std::move(t));
    }
    for (const LinearCircleDeviation& w : id.written)
        d.deviations.push_back({w.name, "", "arcsec", true, w.value, w.lower95, w.upper95, kUnknown});
    for (const LinearCircleReversal& v : id.reversals)
        d.deviations.push_back({"B" + v.axis, "", "um", true, v.value, v.lower95, v.upper95, kUnknown});
    for (const std::string& n : id.notes) d.facts.push_back({"deviation set", n});
    return d;
}

}  // namespace cnccomp::app::report
