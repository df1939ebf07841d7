#include "app/verify_json.hpp"

#include <cmath>

#include <fmt/format.h>

#include "cnccomp/io/markup.hpp"


namespace cnccomp::app {
using namespace cnccomp::io;
namespace {

std::string str(std::string_view s) { return jsonString(s); }


std::string um(double mm) { return jsonNumber(mm / kUm); }

template <class F>
std::string list(size_t n, F item) {
    std::string o = "[";
    for (size_t i = 0; i < n; ++i) o += (i ? ", " : "") + item(i);
    return o + "]";
}

std::string iso(const CircularTestResult& r) {
    return fmt::format("{{\"circular_deviation_G_um\": {}, \"radial_deviation_F_max_um\": {}, \"radial_deviation_F_min_um\": {}, "
                       "\"mean_radial_error_um\": {}, \"centre_um\": [{}, {}]}}",
                       um(r.circularity), um(r.radialMax), um(r.radialMin), um(r.meanRadialError), um(r.center.x()),
                       um(r.center.y()));
}

std::string jsonVecUm(const Vec3& v) { return fmt::format("[{}, {}, {}]", um(v.x()), um(v.y()), um(v.z())); }

std::string pass(const VerifyPass& p) {
    std::string o = fmt::format("{{\"direction\": {}, \"span_before_um\": {}, \"span_after_um\": {}, \"outside_travel\": {}, ",
                                str(p.label), um(p.spanBefore), um(p.spanAfter), p.outsideTravel.empty() ? "null" : str(p.outsideTravel));
    o += fmt::format("\"angle_deg\": {}, ", list(p.before.angleDeg.size(), [&](size_t i) { return jsonNumber(p.before.angleDeg[i]); }));
    if (!p.displacementBefore.empty()) {
        o += fmt::format("\"displacement_before_um\": {}, ",
                         list(p.displacementBefore.size(), [&](size_t i) { return jsonVecUm(p.displacementBefore[i]); }));
        o += fmt::format("\"displacement_after_um\": {}", list(p.displacementAfter.size(), [&](size_t i) { return jsonVecUm(p.displacementAfter[i]); }));
    } else {
        o += fmt::format("\"dL_before_um\": {}, ", list(p.before.dL.size(), [&](size_t i) { return um(p.before.dL[i]); }));
        o += fmt::format("\"dL_after_um\": {}", list(p.after.dL.size(), [&](size_t i) { return um(p.after.dL[i]); }));
    }
    if (p.circular)
        o += fmt::format(", \"iso_before\": {}, \"iso_after\": {}, \"eccentricity_before_um\": {}, \"eccentricity_after_um\": {}",
                         iso(p.isoBefore), iso(p.isoAfter), jsonVecUm(p.eccentricityBefore), jsonVecUm(p.eccentricityAfter));
    return o + "}";
}

}  // namespace

bool verifyGatePassed(const VerifyResult& r, std::optional<double> gateUm, std::optional<double> volumetricGateUm) {
    if (gateUm && !(r.residual / kUm <= *gateUm)) return false;
    if (volumetricGateUm && !(r.volumetric.available && r.volumetric.maxAfter / kUm <= *volumetricGateUm)) return false;
    return true;
}

std::string formatVerifyJson(const VerifyResult& r, std::optional<double> gateUm, std::optional<double> volumetricGateUm) {
    std::string o = "{\n  \"schema\": \"cnccomp-verify/1\",\n";
    o += fmt::format("  \"machine\": {},\n  \"simulated\": {},\n  \"compensation\": {},\n", str(r.machine), str(r.simulated),
                     str(r.compensation));
    o += fmt::format("  \"residual_before_um\": {},\n  \"residual_um\": {},\n", um(r.residualBefore), um(r.residual));
    // `passed` is false when a gate given fails or when the compensation makes the machine worse (a gate that holds
    // whatever the options say): the exit status of verify is 0 exactly when it is true.
    const bool passed = verifyGatePassed(r, gateUm, volumetricGateUm) && !r.worse.any();
    o += fmt::format("  \"makes_machine_worse\": {},\n  \"worse\": {{\"span\": {}, \"volumetric\": {}, \"span_allowance_um\": {}, "
                     "\"volumetric_allowance_um\": {}, \"banner\": {}}},\n",
                     r.worse.any() ? "true" : "false", r.worse.span ? "true" : "false", r.worse.volumetric ? "true" : "false",
                     um(r.worse.spanAllowance), r.volumetric.available ? um(r.worse.volumetricAllowance) : "null",
                     r.worse.any() ? str(worseBanner(r)) : "null");
    o += fmt::format("  \"max_residual_um\": {},\n  \"max_volumetric_um\": {},\n  \"passed\": {},\n",
                     gateUm ? jsonNumber(*gateUm) : "null", volumetricGateUm ? jsonNumber(*volumetricGateUm) : "null", passed ? "true" : "false");
    o += "  \"runs\": [\n";
    for (size_t i = 0; i < r.runs.size(); ++i) {
        const VerifyRun& run = r.runs[i];
        o += fmt::format("    {{\"name\": {}, \"type\": {}, \"kind\": {}, \"program\": {}, \"LB_mm\": {}, \"span_before_um\": {}, "
                         "\"span_after_um\": {},\n     \"passes\": {}}}{}\n",
                         str(run.name), str(run.type), str(postproc::testprog::runKindName(run.kind)), str(run.program), jsonNumber(run.LB),
                         um(run.spanBefore()), um(run.spanAfter()),
                         list(run.passes.size(), [&](size_t k) { return pass(run.passes[k]); }), i + 1 < r.runs.size() ? "," : "");
    }
    o += "  ],\n";
    const VerifyVolumetric& v = r.volumetric;
    o += fmt::format("  \"volumetric\": {{\"available\": {}, \"note\": {}, \"points\": {}, \"tool_lengths_mm\": {}, "
                     "\"max_before_um\": {}, \"rms_before_um\": {}, \"max_after_um\": {}, \"rms_after_um\": {}, "
                     "\"tilt_before_arcsec\": {}, \"tilt_after_arcsec\": {}}},\n",
                     v.available ? "true" : "false", str(v.note), v.points,
                     list(v.toolLengths.size(), [&](size_t i) { return jsonNumber(v.toolLengths[i]); }), um(v.maxBefore), um(v.rmsBefore),
                     um(v.maxAfter), um(v.rmsAfter), jsonNumber(v.tiltBefore / kArcsec), jsonNumber(v.tiltAfter / kArcsec));
    o += fmt::format("  \"remaining\": {}\n}}\n", list(r.remaining.size(), [&](size_t i) {
                         const VerifyRemaining& x = r.remaining[i];
                         // The ISO value under the ISO name, the alias' own value under the alias (VerifyRemaining).
                         return fmt::format("{{\"deviation\": {}, \"reason\": {}, \"iso_name\": {}, \"value\": {}, \"unit\": {}, "
                                            "\"alias\": {}, \"alias_value\": {}}}",
                                            str(x.deviation), str(x.reason), x.valueKnown ? str(x.isoName) : "null",
                                            x.valueKnown ? jsonNumber(x.value) : "null", x.valueKnown ? str(x.unit) : "null",
                                            x.alias.empty() ? "null" : str(x.alias), x.alias.empty() ? "null" : jsonNumber(x.aliasValue));
                     }));
    return o;
}

}  // namespace cnccomp::app
