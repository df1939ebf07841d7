#include "app/report/verification_report.hpp"

#include "app/verify_json.hpp"

#include <cmath>

#include <fmt/format.h>

#include "cnccomp/circular_test.hpp"
#include "cnccomp/map_grid.hpp"

namespace cnccomp::app::report {
using namespace cnccomp::io;

namespace {

/// +1 for a CCW pass, −1 for CW, 0 for a pass that is not a circle direction (R-test forward / reverse).
int passDirection(const std::string& label) { return label == "CCW" ? +1 : label == "CW" ? -1 : 0; }

std::string eccentricityText(const Vec3& e) {
    std::string s;
    for (int c = 0; c < 3; ++c) s += (c ? ", " : "") + (std::isfinite(e[c]) ? fmt::format("{:.3f}", e[c] / kUm) : std::string("–"));
    return "(" + s + ")";
}

/// A ball-bar or DBB5 run whose every pass is a circle direction: the polar plot, ISO 230-4 figures before and after.
std::optional<RunSection> circleSection(const VerifyRun& run) {
    if (run.passes.empty() || run.LB <= 0) return std::nullopt;
    RunSection s;
    s.name = run.name;
    s.test = run.type;
    s.LB = run.LB;
    std::vector<DirectedTrace> before, after;
    for (const VerifyPass& p : run.passes) {
        const int d = passDirection(p.label);
        if (d == 0 || !p.circular) return std::nullopt;
        s.passes.push_back({d, p.before.angleDeg, p.before.dL, p.after.dL});
        before.push_back({d, p.before});
        after.push_back({d, p.after});
        s.notes.push_back(fmt::format("{}: eccentricity (x, y, z) before {} µm, after {} µm", p.label,
                                      eccentricityText(p.eccentricityBefore), eccentricityText(p.eccentricityAfter)));
    }
    s.before = isoFigures(evaluateCircularRun(before, run.LB));
    s.after = isoFigures(evaluateCircularRun(after, run.LB));
    s.notes.insert(s.notes.begin(), fmt::format("test program {}; ΔL span {:.3f} µm before, {:.3f} µm after", run.program,
                                                run.spanBefore() / kUm, run.spanAfter() / kUm));
    return s;
}

ControllerSection compensationSection(const MachineModel& m, const VerifyCompensation& c, const VerifyResult& r,
                                      const VerificationReportInputs& in) {
    ControllerSection s;
    s.files = c.files;
    switch (c.kind) {
        case VerifyCompensation::Kind::Deviations:
            s.name = "ideal";
            if (in.compensationSet)
                for (size_t i = 0; i < m.deviations.size(); ++i)
                    if (in.compensationSet->present[i])
                        s.compensated.push_back({m.deviations[i].name, "exact model (a perfect TCP controller)", kUnknown, ""});
            break;
        case VerifyCompensation::Kind::ControllerFiles: s.name = c.backend; break;
        case VerifyCompensation::Kind::CorrectedPrograms: s.name = "corrected test programs"; break;
        case VerifyCompensation::Kind::None: break;
    }
    for (const controllers::Coverage& x : c.compensated) s.compensated.push_back({x.deviation, x.note, kUnknown, ""});
    for (const VerifyRemaining& x : r.remaining)
        s.notCompensated.push_back({x.deviation, x.reason, x.valueKnown ? x.value : kUnknown, x.valueKnown ? x.unit : "", x.alias,
                                    x.alias.empty() ? kUnknown : x.aliasValue});
    const VerifyVolumetric& v = r.volumetric;
    if (v.available) {
        s.beforeMax = v.maxBefore;
        s.beforeRms = v.rmsBefore;
        s.afterMax = v.maxAfter;
        s.afterRms = v.rmsAfter;
        s.points = static_cast<int>(v.points);
    }
    s.spanBefore = r.residualBefore;
    s.spanAfter = r.residual;
    s.basis = fmt::format("{}; tool tip: {}", r.simulated, v.note);
    return s;
}

}  // namespace

ReportData verificationReport(const MachineModel& m, const DeviationSet& simulated, const VerifyCompensation& comp,
                              const VerifyResult& r, const VerificationReportInputs& in) {
    ReportData d;
    d.title = fmt::format("Verification of {}: {}", r.machine, r.compensation);
    d.machine = r.machine;
    d.machineModel = &m;
    d.facts = {{"machine file", in.machineFile},
               {"plan", in.planFile},
               {"compensation", fmt::format("{} ({})", r.compensation, in.compensationPath)},
               {"machine the commands reach", r.simulated},
               {"test programs", fmt::format("{} dialect, generated as cnccomp testprog writes them and read back (the "
                                             "commands as written, never recomputed)",
                                             in.dialect)},
               {"residual", fmt::format("largest ΔL span after compensation {:.3f} µm (before {:.3f} µm)", r.residual / kUm,
                                        r.residualBefore / kUm)}};
    // The gate that holds whatever the options say (verify.hpp VerifyWorse): first on the page when it fails.
    if (r.worse.any()) d.alarms.push_back(worseBanner(r));
    d.facts.push_back({"against no compensation",
                       r.worse.any() ? "WORSE than none: exit status 1"
                                     : fmt::format("not worse than none (growth allowed: max(0.1 µm, 1 % of before) = {:.3f} µm of span)",
                                                   r.worse.spanAllowance / kUm)});
    if (in.gateUm)
        d.facts.push_back({"gate", fmt::format("--max-residual-um {:g}: {}", *in.gateUm,
                                               r.residual / kUm <= *in.gateUm ? "passed" : "FAILED (exit status 1)")});
    if (in.volumetricGateUm)
        d.facts.push_back({"volumetric gate",
                           fmt::format("--max-volumetric-um {:g}: {}", *in.volumetricGateUm,
                                       verifyGatePassed(r, std::nullopt, in.volumetricGateUm) ? "passed"
                                                                                               : "FAILED (exit status 1)")});
    d.afterNote = fmt::format("the same test programs through the compensation ({})", r.compensation);
    for (const VerifyRun& run : r.runs) {
        if (auto s = circleSection(run)) d.runs.push_back(std::move(*s));
        for (const VerifyPass& p : run.passes) {
            d.spans.push_back({run.name, run.type, p.label, p.displacementBefore.empty() ? "dL" : "displacement", p.spanBefore,
                               p.spanAfter, p.outsideTravel.empty() ? "" : "compensated commands leave the travel: " + p.outsideTravel});
            if (!p.outsideTravel.empty())
                d.warnings.push_back(fmt::format("run '{}' {}: the compensated commands leave the travel: {} (a real control "
                                                 "would stop with a limit alarm)",
                                                 run.name, p.label, p.outsideTravel));
        }
    }
    d.controllers.push_back(compensationSection(m, comp, r, in));
    if (comp.model) {
        MapOptions mo = in.map;
        mo.toolLength = r.volumetric.toolLengths.empty() ? 0.0 : r.volumetric.toolLengths.front();
        const MapPlane plane = parseMapPlane(mo.plane);
        const VolumetricMap before = uncompensatedMap(m, simulated, mo);
        d.maps.push_back({fmt::format("before compensation: {}, tool length {:g} mm", r.simulated, mo.toolLength), before, plane});
        d.maps.push_back({fmt::format("after compensation: {}", r.compensation),
                          compensatedMap(before, m, simulated, *comp.model, mo.toolLength), plane});
    } else {
        d.facts.push_back({"maps", "none: a corrected program compensates its own poses only (no model of the whole workspace)"});
    }
    return d;
}

}  // namespace cnccomp::app::report
