#include "cnccomp/io/linear_circle_json.hpp"

#include <cmath>

#include <fmt/format.h>

#include "cnccomp/geometry.hpp"
#include "cnccomp/io/markup.hpp"

namespace cnccomp {

namespace {

std::string num(double v) { return std::isfinite(v) ? fmt::format("{:.9g}", v) : "null"; }
std::string str(const std::string& s) { return jsonString(s); }

template <class T, class F>
std::string array(const std::vector<T>& v, F item) {
    std::string o = "[";
    for (size_t i = 0; i < v.size(); ++i) o += (i ? ", " : "") + item(v[i]);
    return o + "]";
}

std::string direction(int d) { return d > 0 ? "\"ccw\"" : "\"cw\""; }

std::string conditions(const LinearCircleConditions& c) {
    return fmt::format(
        "{{\"file\": {}, \"layout\": {}, \"plane\": {}, \"centre_mm\": [{}, {}, {}], \"radius_mm\": {}, \"start_deg\": {}, "
        "\"arc_deg\": {}, \"feed_mm_min\": {}, \"overshoot_deg\": {}, \"tool_length_mm\": {}, \"directions\": {}, "
        "\"samples\": {}, \"spacing_deg\": {}, \"sample_rate_hz\": {}, \"feed_from_data_mm_min\": {}, \"date\": {}, "
        "\"instrument\": {}, \"operator\": {}, \"length\": {}}}",
        str(c.file), str(c.layout), str(linearPlaneName(c.plane)), num(c.centre.x()), num(c.centre.y()), num(c.centre.z()),
        num(c.radius), num(c.startDeg), num(c.arcDeg), num(c.feed), num(c.overshootDeg), num(c.toolLength),
        array(c.directions, direction), array(c.samples, [](int n) { return std::to_string(n); }), num(c.spacingDeg),
        num(c.sampleRateHz), c.feedFromData > 0 ? num(c.feedFromData) : "null", c.date.empty() ? "null" : str(c.date),
        c.instrument.empty() ? "null" : str(c.instrument), c.operatorName.empty() ? "null" : str(c.operatorName),
        c.relativeLength ? "\"relative\"" : "\"absolute\"");
}

std::string iso(const CircularRunResult& r) {
    std::string passes = "[";
    for (size_t i = 0; i < r.passes.size(); ++i) {
        const CircularTestResult& p = r.passes[i];
        passes += fmt::format("{}{{\"direction\": {}, \"samples\": {}, \"G_um\": {}, \"F_max_um\": {}, \"F_min_um\": {}, "
                              "\"mean_radius_mm\": {}}}",
                              i ? ", " : "", direction(r.directions[i]), p.samples, num(p.circularity / kUm),
                              num(p.radialMax / kUm), num(p.radialMin / kUm), num(p.meanRadius));
    }
    passes += "]";
    return fmt::format("{{\"G_um\": {}, \"H_um\": {}, \"F_max_um\": {}, \"F_min_um\": {}, \"mean_radius_mm\": {}, \"passes\": {}}}",
                       num(r.circularDeviation / kUm), num(r.hysteresis / kUm), num(r.radialMax / kUm),
                       num(r.radialMin / kUm), num(r.meanRadius), passes);
}

}  // namespace

std::string formatLinearCircleJson(const std::string& machine, const LinearCircleIdentification& id) {
    std::string o = "{\n  \"schema\": \"cnccomp-linear-circles/1\",\n";
    o += fmt::format("  \"machine\": {},\n  \"method\": \"circle\",\n  \"runs\": [", str(machine));
    for (size_t i = 0; i < id.runs.size(); ++i) {
        const LinearCircleRunResult& r = id.runs[i];
        const LinearCircleFit& f = r.fit;
        o += i ? ",\n    {" : "\n    {";
        o += fmt::format("\"name\": {},\n     \"conditions\": {},\n     \"iso230_4\": {},\n", str(r.run),
                         conditions(r.conditions), iso(r.iso));
        o += fmt::format("     \"fit\": {{\"observations\": {}, \"unknowns\": {}, \"rank\": {}, \"dof\": {}, \"iterations\": {}, "
                         "\"sigma_um\": {}, \"rms_before_um\": {}, \"measured_circularity_um\": {}}},\n",
                         f.observations, f.unknowns, f.rank, f.dof, f.iterations, num(f.sigma), num(f.rmsBefore),
                         num(f.measuredCircularity));
        o += "     \"diagnostics\": [";
        for (size_t k = 0; k < f.diagnostics.size(); ++k) {
            const LinearCircleDiagnostic& d = f.diagnostics[k];
            o += fmt::format("{}\n       {{\"rank\": {}, \"name\": {}, \"unit\": {}, \"identified\": {}, \"value\": {}, "
                             "\"low95\": {}, \"high95\": {}, \"circularity_um\": {}, \"share_pct\": {}, \"model\": {}}}",
                             k ? "," : "", d.identified ? std::to_string(k + 1) : "null", str(d.name), str(d.unit),
                             d.identified ? "true" : "false", num(d.value), num(d.lower95), num(d.upper95), num(d.circularity),
                             num(d.share), str(d.model));
        }
        o += "],\n     \"parameters\": [";
        for (size_t k = 0; k < f.parameters.size(); ++k) {
            const LinearCircleParameter& p = f.parameters[k];
            o += fmt::format("{}\n       {{\"name\": {}, \"unit\": {}, \"nuisance\": {}, \"identified\": {}, \"value\": {}, "
                             "\"std\": {}, \"low95\": {}, \"high95\": {}}}",
                             k ? "," : "", str(p.name), str(p.unit), p.nuisance ? "true" : "false",
                             p.identified ? "true" : "false", num(p.value), num(p.stddev), num(p.lower95), num(p.upper95));
        }
        o += "],\n     \"centring_um\": " + array(f.nuisance.centring, [](const Eigen::Vector2d& c) {
                 return fmt::format("[{}, {}]", num(c.x()), num(c.y()));
             });
        o += fmt::format(",\n     \"radius_offset_um\": {},\n", num(f.nuisance.radiusOffset));
        o += "     \"confounded\": " + array(f.confounded, [](const std::vector<std::string>& g) { return array(g, str); });
        o += ",\n     \"identifiable\": " + array(f.identifiable, [](const LinearCircleCombination& c) {
                 return fmt::format("{{\"text\": {}, \"value\": {}, \"std\": {}}}", str(c.text), num(c.value), num(c.stddev));
             });
        o += ",\n     \"warnings\": " + array(f.warnings, str) + "}";
    }
    o += "\n  ],\n  \"deviations\": " + array(id.written, [](const LinearCircleDeviation& d) {
             return fmt::format("{{\"name\": {}, \"unit\": \"arcsec\", \"value\": {}, \"std\": {}, \"low95\": {}, \"high95\": {}, "
                                "\"um_per_m_per_arcsec\": {}, \"runs\": {}}}",
                                str(d.name), num(d.value), num(d.stddev), num(d.lower95), num(d.upper95), num(d.perArcsec),
                                array(d.runs, str));
         });
    o += ",\n  \"notes\": " + array(id.notes, str) + "\n}\n";
    return o;
}

}  // namespace cnccomp
