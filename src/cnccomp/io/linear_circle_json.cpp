#include "cnccomp/io/linear_circle_json.hpp"

#include <cmath>

#include <fmt/format.h>

#include "cnccomp/geometry.hpp"
#include "cnccomp/io/markup.hpp"

namespace cnccomp::io {

// Internals in a named namespace (not anonymous): the core may be compiled as unity units.
namespace linear_circle_json_detail {

std::string lcNum(double v) { return jsonNumber(v, 9); }
std::string lcStr(const std::string& s) { return jsonString(s); }

template <class T, class F>
std::string lcArray(const std::vector<T>& v, F item) {
    std::string o = "[";
    for (size_t i = 0; i < v.size(); ++i) o += (i ? ", " : "") + item(v[i]);
    return o + "]";
}

std::string lcDirection(int d) { return d > 0 ? "\"ccw\"" : "\"cw\""; }

std::string lcConditions(const LinearCircleConditions& c) {
    return fmt::format(
        "{{\"file\": {}, \"layout\": {}, \"plane\": {}, \"centre_mm\": [{}, {}, {}], \"radius_mm\": {}, \"start_deg\": {}, "
        "\"arc_deg\": {}, \"feed_mm_min\": {}, \"overshoot_deg\": {}, \"tool_length_mm\": {}, \"directions\": {}, "
        "\"samples\": {}, \"spacing_deg\": {}, \"sample_rate_hz\": {}, \"feed_from_data_mm_min\": {}, \"date\": {}, "
        "\"instrument\": {}, \"operator\": {}, \"length\": {}}}",
        lcStr(c.file), lcStr(c.layout), lcStr(linearPlaneName(c.plane)), lcNum(c.centre.x()), lcNum(c.centre.y()), lcNum(c.centre.z()),
        lcNum(c.radius), lcNum(c.startDeg), lcNum(c.arcDeg), lcNum(c.feed), lcNum(c.overshootDeg), lcNum(c.toolLength),
        lcArray(c.directions, lcDirection), lcArray(c.samples, [](int n) { return std::to_string(n); }), lcNum(c.spacingDeg),
        lcNum(c.sampleRateHz), c.feedFromData > 0 ? lcNum(c.feedFromData) : "null", c.date.empty() ? "null" : lcStr(c.date),
        c.instrument.empty() ? "null" : lcStr(c.instrument), c.operatorName.empty() ? "null" : lcStr(c.operatorName),
        c.relativeLength ? "\"relative\"" : "\"absolute\"");
}

std::string lcIso(const CircularRunResult& r) {
    std::string passes = "[";
    for (size_t i = 0; i < r.passes.size(); ++i) {
        const CircularTestResult& p = r.passes[i];
        passes += fmt::format("{}{{\"direction\": {}, \"samples\": {}, \"G_um\": {}, \"F_max_um\": {}, \"F_min_um\": {}, "
                              "\"mean_radius_mm\": {}}}",
                              i ? ", " : "", lcDirection(r.directions[i]), p.samples, lcNum(p.circularity / kUm),
                              lcNum(p.radialMax / kUm), lcNum(p.radialMin / kUm), lcNum(p.meanRadius));
    }
    passes += "]";
    return fmt::format("{{\"G_um\": {}, \"H_um\": {}, \"F_max_um\": {}, \"F_min_um\": {}, \"mean_radius_mm\": {}, \"passes\": {}}}",
                       lcNum(r.circularDeviation / kUm), lcNum(r.hysteresis / kUm), lcNum(r.radialMax / kUm),
                       lcNum(r.radialMin / kUm), lcNum(r.meanRadius), passes);
}

}  // namespace linear_circle_json_detail

std::string formatLinearCircleJson(const std::string& machine, const LinearCircleIdentification& id) {
    using namespace linear_circle_json_detail;
    std::string o = "{\n  \"schema\": \"cnccomp-linear-circles/1\",\n";
    o += fmt::format("  \"machine\": {},\n  \"method\": \"circle\",\n  \"runs\": [", lcStr(machine));
    for (size_t i = 0; i < id.runs.size(); ++i) {
        const LinearCircleRunResult& r = id.runs[i];
        const LinearCircleFit& f = r.fit;
        o += i ? ",\n    {" : "\n    {";
        o += fmt::format("\"name\": {},\n     \"conditions\": {},\n     \"iso230_4\": {},\n", lcStr(r.run),
                         lcConditions(r.conditions), lcIso(r.iso));
        o += fmt::format("     \"fit\": {{\"observations\": {}, \"unknowns\": {}, \"rank\": {}, \"dof\": {}, \"iterations\": {}, "
                         "\"sigma_um\": {}, \"rms_before_um\": {}, \"measured_circularity_um\": {}}},\n",
                         f.observations, f.unknowns, f.rank, f.dof, f.iterations, lcNum(f.sigma), lcNum(f.rmsBefore),
                         lcNum(f.measuredCircularity));
        o += "     \"diagnostics\": [";
        for (size_t k = 0; k < f.diagnostics.size(); ++k) {
            const LinearCircleDiagnostic& d = f.diagnostics[k];
            o += fmt::format("{}\n       {{\"rank\": {}, \"name\": {}, \"unit\": {}, \"identified\": {}, \"value\": {}, "
                             "\"low95\": {}, \"high95\": {}, \"circularity_um\": {}, \"share_pct\": {}, \"model\": {}}}",
                             k ? "," : "", d.identified ? std::to_string(k + 1) : "null", lcStr(d.name), lcStr(d.unit),
                             d.identified ? "true" : "false", lcNum(d.value), lcNum(d.lower95), lcNum(d.upper95), lcNum(d.circularity),
                             lcNum(d.share), lcStr(d.model));
        }
        o += "],\n     \"parameters\": [";
        for (size_t k = 0; k < f.parameters.size(); ++k) {
            const LinearCircleParameter& p = f.parameters[k];
            o += fmt::format("{}\n       {{\"name\": {}, \"unit\": {}, \"nuisance\": {}, \"identified\": {}, \"value\": {}, "
                             "\"std\": {}, \"low95\": {}, \"high95\": {}}}",
                             k ? "," : "", lcStr(p.name), lcStr(p.unit), p.nuisance ? "true" : "false",
                             p.identified ? "true" : "false", lcNum(p.value), lcNum(p.stddev), lcNum(p.lower95), lcNum(p.upper95));
        }
        o += "],\n     \"centring_um\": " + lcArray(f.nuisance.centring, [](const Eigen::Vector2d& c) {
                 return fmt::format("[{}, {}]", lcNum(c.x()), lcNum(c.y()));
             });
        o += fmt::format(",\n     \"radius_offset_um\": {},\n", lcNum(f.nuisance.radiusOffset));
        o += "     \"confounded\": " + lcArray(f.confounded, [](const std::vector<std::string>& g) { return lcArray(g, lcStr); });
        o += ",\n     \"identifiable\": " + lcArray(f.identifiable, [](const LinearCircleCombination& c) {
                 return fmt::format("{{\"text\": {}, \"value\": {}, \"std\": {}}}", lcStr(c.text), lcNum(c.value), lcNum(c.stddev));
             });
        o += ",\n     \"warnings\": " + lcArray(f.warnings, lcStr) + "}";
    }
    o += "\n  ],\n  \"deviations\": " + lcArray(id.written, [](const LinearCircleDeviation& d) {
             return fmt::format("{{\"name\": {}, \"unit\": \"arcsec\", \"value\": {}, \"std\": {}, \"low95\": {}, \"high95\": {}, "
                                "\"um_per_m_per_arcsec\": {}, \"runs\": {}}}",
                                lcStr(d.name), lcNum(d.value), lcNum(d.stddev), lcNum(d.lower95), lcNum(d.upper95), lcNum(d.perArcsec),
                                lcArray(d.runs, lcStr));
         });
    o += ",\n  \"reversals\": " + lcArray(id.reversals, [](const LinearCircleReversal& v) {
             return fmt::format("{{\"name\": {}, \"unit\": \"um\", \"value\": {}, \"std\": {}, \"low95\": {}, \"high95\": {}, "
                                "\"from\": {}}}",
                                lcStr("B" + v.axis), lcNum(v.value), lcNum(v.stddev), lcNum(v.lower95), lcNum(v.upper95),
                                lcArray(v.from, lcStr));
         });
    o += ",\n  \"notes\": " + lcArray(id.notes, lcStr) + "\n}\n";
    return o;
}

}  // namespace cnccomp::io
