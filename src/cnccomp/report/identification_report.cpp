#include "cnccomp/report/identification_report.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/map_grid.hpp"
#include "cnccomp/volumetric_map.hpp"
#include "controllers/backend.hpp"
#include "controllers/common/evaluate.hpp"

namespace cnccomp::report {

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

namespace {

/// True where the tool axis is (nearly) parallel to a rotary axis: there a TCP controller has no unique answer (any
/// angle of that axis gives the same tool axis) and its model is not a prediction of the machine.
bool singularPose(const Kinematics& k, const AxisVector& q) {
    const Vec3 axis = k.baseToTool(q).linear() * k.machine().toolDirection;
    for (const JointFrame& j : k.jointFrames(q))
        if (j.rotary && j.direction.cross(axis).norm() < 0.1) return true;
    return false;
}

/// X and Y over their travel (≤ ±200 mm, 21 points); the other linear axes at 0 (or the nearest end of their travel);
/// the rotary axes at 0, or, where that pose is singular, at the first of 30°, 45°, −30°, 60° that is not (and lies in
/// the axis's travel).
std::string defaultGrid(const MachineModel& m) {
    const Kinematics k(m);
    AxisVector q = AxisVector::Zero(m.axisCount());
    for (int a = 0; a < m.axisCount(); ++a) q[a] = std::clamp(0.0, m.axisLink(a).min, m.axisLink(a).max);
    for (int a = 0; a < m.axisCount() && singularPose(k, q); ++a) {
        const Link& l = m.axisLink(a);
        if (l.kind != AxisKind::Rotary) continue;
        for (double deg : {30.0, 45.0, -30.0, 60.0}) {
            AxisVector t = q;
            t[a] = deg * kDeg;
            if (t[a] < l.min || t[a] > l.max || singularPose(k, t)) continue;
            q = t;
            break;
        }
    }
    std::string g;
    for (int a = 0; a < m.axisCount(); ++a) {
        const Link& l = m.axisLink(a);
        const std::string& n = m.axisNames[a];
        if ((n == "X" || n == "Y") && l.kind == AxisKind::Linear) {
            const double lo = std::max(l.min, -200.0), hi = std::min(l.max, 200.0);
            if (hi - lo > 1e-6) {
                g += fmt::format("{}{}={:g}:{:g}:{:g}", g.empty() ? "" : " ", n, lo, hi, (hi - lo) / 20);
                continue;
            }
        }
        g += fmt::format("{}{}={:g}", g.empty() ? "" : " ", n, q[a] / (l.kind == AxisKind::Rotary ? kDeg : 1.0));
    }
    return g;
}

/// The map of `before` recomputed with the controller's drive commands: tip error of the identified machine.
VolumetricMap compensatedMap(const VolumetricMap& before, const MachineModel& m, const DeviationSet& identified,
                             const controllers::AppliedCompensation& comp, double toolLength) {
    VolumetricMap map = before;
    const Kinematics actual(m, identified), nominal(m);
    const Vec3 tipActual = actual.toolPoint(toolLength), tipNominal = nominal.toolPoint(toolLength);
    double sum = 0;
    map.stats.norm = {};
    long n = 0;
    AxisVector q(m.axisCount());
    for (MapPoint& p : map.points) {
        if (!p.ok) continue;
        for (int a = 0; a < m.axisCount(); ++a) q[a] = p.q[static_cast<size_t>(a)];
        const AxisVector drive = comp.driveCommandsForTool(q, toolLength);
        p.error = actual.toolPointInWorkpiece(drive, tipActual) - nominal.toolPointInWorkpiece(q, tipNominal);
        p.rotation.setZero();
        p.tilt = 0;
        map.stats.norm.maxAbs = std::max(map.stats.norm.maxAbs, p.error.norm());
        sum += p.error.squaredNorm();
        ++n;
    }
    map.stats.norm.rms = n > 0 ? std::sqrt(sum / static_cast<double>(n)) : 0.0;
    return map;
}

}  // namespace

void addCompensationSections(ReportData& data, const MachineModel& m, const DeviationSet& identified,
                             const std::vector<std::string>& names, const MapOptions& o) {
    MapRequest req{m, identified, parseGrid(o.grid.empty() ? defaultGrid(m) : o.grid, "report map grid"), o.toolLength, {}, 0};
    const MapPlane plane = parseMapPlane(o.plane);
    const VolumetricMap before = computeMap(req);
    data.machineModel = &m;
    data.maps.push_back({fmt::format("before compensation: the identified machine, tool length {:g} mm", o.toolLength), before, plane});
    if (names.empty()) return;
    std::vector<AxisVector> samples;
    const Kinematics nominal(m);
    for (const AxisVector& q : controllers::workspaceSamples(m, 5))
        if (!singularPose(nominal, q)) samples.push_back(q);
    for (const std::string& name : names) {
        const controllers::Backend& b = controllers::backend(name);
        const controllers::EmitResult emitted = b.emit({m, identified, "identified deviations", "2000-01-01"});
        const auto comp = b.apply(m, emitted.files);
        const controllers::CompensationFigures f =
            controllers::evaluateCompensation(m, identified, *comp, samples, o.toolLength);
        ControllerSection c;
        c.name = name;
        for (const auto& x : emitted.compensated) c.compensated.emplace_back(x.deviation, x.note);
        for (const auto& x : emitted.notCompensated) c.notCompensated.emplace_back(x.deviation, x.note);
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

}  // namespace cnccomp::report
