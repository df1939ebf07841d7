#include "app/report/identification_report.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/map_grid.hpp"
#include "app/report/compensation_map.hpp"
#include "cnccomp/volumetric_map.hpp"
#include "controllers/backend.hpp"
#include "controllers/common/evaluate.hpp"

namespace cnccomp::app::report {
using namespace cnccomp::identification;
using namespace cnccomp::io;
using namespace cnccomp::measurement;

namespace {

/// Splits concatenated per-sample values back into the passes of a measured trace.
std::vector<std::vector<double>> perPass(const MeasuredTrace& t, const std::vector<double>& all) {
    std::vector<std::vector<double>> out;
    size_t k = 0;
    for (const DirectedTrace& p : t.passes) {
        out.emplace_back(all.begin() + static_cast<long>(k), all.begin() + static_cast<long>(k + p.trace.dL.size()));
        k += p.trace.dL.size();
    }
    return out;
}

CircularRunResult evaluate(const MeasuredTrace& t, const std::vector<std::vector<double>>& values, double LB) {
    std::vector<DirectedTrace> passes;
    for (size_t i = 0; i < t.passes.size(); ++i) passes.push_back({t.passes[i].direction, {t.passes[i].trace.angleDeg, values[i]}});
    return evaluateCircularRun(passes, LB);
}

}  // namespace

std::vector<RunSection> measuredRunSections(const MachineModel& m, const MeasurementPlan& plan, const MeasuredRuns& measured,
                                            const IdentificationResult& result) {
    if (measured.ballbar.size() != plan.runs.size() || measured.observations.size() < plan.runs.size())
        throw ModelError("report: the measured runs do not match the plan");
    const Kinematics identified(m, result.deviations), nominal(m);
    std::vector<RunSection> out;
    int nuisance = 0;
    for (size_t i = 0; i < plan.runs.size(); ++i) {
        const BallbarRun& run = plan.runs[i];
        const MeasuredTrace& t = measured.ballbar[i];
        const ObservationModel& o = *measured.observations[i];
        const int nn = o.nuisanceCount();
        if (nuisance + nn > result.nuisance.size()) throw ModelError("report: nuisance parameters do not match the runs");
        const double* nu = result.nuisance.data() + nuisance;
        nuisance += nn;
        const size_t n = static_cast<size_t>(o.size());
        if (n != t.trace.dL.size()) throw ModelError(fmt::format("report: run '{}' has {} samples, its observation {}", run.name,
                                                                 t.trace.dL.size(), n));
        std::vector<double> pid(n), p0(n), before(n), after(n);
        o.predict(identified, nu, pid.data());
        o.predict(nominal, nu, p0.data());
        const bool relative = dynamic_cast<const LengthOffsetObservation*>(&o) != nullptr;
        const double dL0 = relative ? nu[nn - 1] : 0.0;
        for (size_t k = 0; k < n; ++k) {
            before[k] = t.trace.dL[k] - dL0;
            after[k] = before[k] - (pid[k] - p0[k]);
        }
        RunSection s;
        s.name = run.name;
        s.test = std::string(testName(run.test));
        s.LB = run.LB;
        const auto b = perPass(t, before), a = perPass(t, after);
        for (size_t p = 0; p < t.passes.size(); ++p) s.passes.push_back({t.passes[p].direction, t.passes[p].trace.angleDeg, b[p], a[p]});
        s.before = isoFigures(evaluate(t, b, run.LB));
        s.after = isoFigures(evaluate(t, a, run.LB));
        for (const RunResidual& r : result.report.runs)
            if (r.run == run.name) s.rmsBefore = r.rmsBefore, s.rmsAfter = r.rmsAfter;
        const TraceImportSummary& sum = t.summary;
        s.notes.push_back(fmt::format("{}-sampled file: {} rows, {} kept, {} missing, {} outside the sweep (overshoot)", sum.layout,
                                      sum.rows, t.trace.dL.size(), sum.missing, sum.trimmed));
        if (sum.binnedFrom > 0)
            s.notes.push_back(fmt::format("{} samples in the sweep averaged into {} bins of the plan's {:g}° step (more than "
                                          "four samples a step)", sum.binnedFrom, sum.binnedInto, std::abs(run.stepDeg)));
        if (sum.feedEstimate > 0)
            s.notes.push_back(fmt::format("feed from the passes' durations: {:.1f} mm/min (plan {:g}, within {:.2f} %)",
                                          sum.feedEstimate, run.capture.feed, 100 * sum.feedTolerance));
        if (run.capture.removeDrift) s.notes.push_back(fmt::format("drift removed: {:.3f} µm over the file", sum.driftRemoved / kUm));
        if (relative)
            s.notes.push_back(fmt::format("relative instrument: length offset dL0 = {:.3f} µm estimated and taken off", dL0 / kUm));
        out.push_back(std::move(s));
    }
    return out;
}

std::vector<DeviationRow> deviationRows(const IdentificationReport& r) {
    std::vector<DeviationRow> out;
    for (const ParameterEstimate& p : r.parameters) {
        if (p.nuisance) continue;
        DeviationRow d;
        d.name = p.name;
        d.alias = p.alias;
        d.unit = p.unit();
        d.identified = p.identified;
        const double s = p.displayScale();
        if (p.identified) {
            d.value = p.value / s;
            d.low95 = p.lower95 / s;
            d.high95 = p.upper95 / s;
        }
        out.push_back(std::move(d));
    }
    return out;
}

void addCompensationSections(ReportData& data, const MachineModel& m, const DeviationSet& identified,
                             const std::vector<std::string>& names, const MapOptions& o) {
    const MapPlane plane = parseMapPlane(o.plane);
    const VolumetricMap before = uncompensatedMap(m, identified, o);
    data.machineModel = &m;
    data.maps.push_back({fmt::format("before compensation: the identified machine, tool length {:g} mm", o.toolLength), before, plane});
    if (names.empty()) return;
    const std::vector<AxisVector> samples = regularWorkspaceSamples(m, 5);
    for (const std::string& name : names) {
        const controllers::Backend& b = controllers::backend(name);
        const controllers::EmitResult emitted = b.emit({m, identified, "identified deviations", "2000-01-01"});
        const auto comp = b.apply(m, emitted.files);
        const controllers::common::CompensationFigures f =
            controllers::common::evaluateCompensation(m, identified, *comp, samples, o.toolLength);
        ControllerSection c;
        c.name = name;
        for (const auto& x : emitted.compensated) c.compensated.push_back({x.deviation, x.note, kUnknown, ""});
        for (const auto& x : emitted.notCompensated) c.notCompensated.push_back({x.deviation, x.note, kUnknown, ""});
        c.beforeMax = f.maxBefore;
        c.beforeRms = f.rmsBefore;
        c.afterMax = f.maxAfter;
        c.afterRms = f.rmsAfter;
        c.points = f.points;
        c.basis = fmt::format("predicted: {} read back and applied to the identified machine, {} workspace poses (tool axis "
                              "not parallel to a rotary axis), tool length {:g} mm (files not written: cnccomp emit --controller {})",
                              name, f.points, o.toolLength, name);
        data.controllers.push_back(std::move(c));
        data.maps.push_back({fmt::format("after compensation by {} (predicted)", name),
                             compensatedMap(before, m, identified, *comp, o.toolLength), plane});
    }
}

}  // namespace cnccomp::app::report
