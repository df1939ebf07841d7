#include "cnccomp/linear_circle_identify.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/linear_circle_trace.hpp"
#include "cnccomp/io/plan_measurements_io.hpp"
#include "cnccomp/kinematics.hpp"

namespace cnccomp {
using namespace cnccomp::io;
using namespace cnccomp::measurement;

// Internals in a named namespace (not anonymous): the core may be compiled as unity units.
namespace linear_circle_identify_detail {

/// The recorded passes as the model's passes (angles already inside the data arc).
std::vector<LinearCirclePass> lcModelPasses(const LinearCircleRun& run, const std::vector<DirectedTrace>& traces) {
    std::vector<LinearCirclePass> out;
    for (const DirectedTrace& t : traces) {
        LinearCirclePass p;
        p.direction = t.direction;
        p.feed = run.capture.feed;
        p.startDeg = t.direction > 0 ? run.startDeg : run.endDeg();
        p.sweepDeg = run.arcDeg;
        p.angleDeg = t.trace.angleDeg;
        p.dL = t.trace.dL;
        out.push_back(std::move(p));
    }
    return out;
}

/// ISO 230-1 name of the squareness of a plane's axes in the machine: the rotation of the downstream slide of the two,
/// EC0Y / EA0Z / EB0Z for slides stacked X → Y → Z, EC0X / EA0Y / EB0X where the chain stacks them the other way (a
/// table X on a saddle Y). The first the machine has; the preferred name when it has none.
std::string lcSquarenessName(const MachineModel& m, LinearPlane p) {
    const std::array<const char*, 2> names = p == LinearPlane::XY   ? std::array<const char*, 2>{"EC0Y", "EC0X"}
                                             : p == LinearPlane::YZ ? std::array<const char*, 2>{"EA0Z", "EA0Y"}
                                                                    : std::array<const char*, 2>{"EB0Z", "EB0X"};
    for (const char* n : names)
        if (m.deviationIndex(n) >= 0) return n;
    return names[0];
}

const LinearCircleParameter* lcParameter(const LinearCircleFit& fit, const std::string& name) {
    for (const LinearCircleParameter& p : fit.parameters)
        if (p.name == name) return &p;
    return nullptr;
}

}  // namespace linear_circle_identify_detail

LinearCircleIdentification identifyLinearCircleRuns(const MachineModel& m, const std::vector<LinearCircleRun>& runs,
                                                    const std::string& dir, const LinearCircleSettings& base) {
    if (runs.empty()) throw ModelError("the plan has no circle runs (<circle>)");
    MeasurementPlan plan;
    plan.circleRuns = runs;
    MeasurementKinds kinds;
    kinds.circles = true;
    return identifyLinearCircleRuns(m, runs, loadPlanMeasurements(m, plan, dir, kinds).circles, base);
}

LinearCircleIdentification identifyLinearCircleRuns(const MachineModel& m, const std::vector<LinearCircleRun>& runs,
                                                    const std::vector<LinearCircleTrace>& files,
                                                    const LinearCircleSettings& base) {
    using namespace linear_circle_identify_detail;
    if (runs.empty()) throw ModelError("the plan has no circle runs (<circle>)");
    if (files.size() != runs.size()) throw ModelError("the measurements of the plan's circle runs were not read");
    LinearCircleIdentification out{{}, DeviationSet(m), {}, {}, {}};
    for (size_t k = 0; k < runs.size(); ++k) {
        const LinearCircleRun& run = runs[k];
        const LinearCircleTrace& file = files[k];
        const std::string& path = file.measured.path;
        LinearCircleRunResult r;
        r.run = run.name;
        r.summary = file.measured.summary;
        r.circle = run.circle();
        r.passes = lcModelPasses(run, file.measured.passes);
        LinearCircleSettings settings = base;
        settings.cyclicPitch = run.cyclicPitch;
        try {
            r.fit = identifyLinearCircle(r.circle, r.passes, settings);
        } catch (const ModelError& e) {
            throw InputError(path, 0, e.what());
        }
        r.iso = evaluateCircularRun(file.measured.passes, run.radius);
        for (const LinearCirclePass& p : r.passes) {
            const std::vector<double> effect =
                predictLinearCircle(r.circle, p, r.fit.values, Eigen::Vector2d::Zero(), 0.0, settings);
            std::vector<double> a(p.dL.size());
            for (size_t i = 0; i < a.size(); ++i) a[i] = p.dL[i] - effect[i];
            r.after.push_back(std::move(a));
        }
        LinearCircleConditions& c = r.conditions;
        c.file = path;
        c.layout = r.summary.layout;
        c.plane = run.plane;
        c.centre = run.centre;
        c.radius = run.radius;
        c.startDeg = run.startDeg;
        c.arcDeg = run.arcDeg;
        c.feed = run.capture.feed;
        c.overshootDeg = run.capture.overshootDeg;
        c.toolLength = run.toolLength;
        c.directions = run.directions();
        double spacing = 0;
        int gaps = 0;
        for (const LinearCirclePass& p : r.passes) {
            c.samples.push_back(static_cast<int>(p.angleDeg.size()));
            for (size_t i = 1; i < p.angleDeg.size(); ++i) spacing += std::abs(p.angleDeg[i] - p.angleDeg[i - 1]), ++gaps;
        }
        c.spacingDeg = gaps > 0 ? spacing / gaps : 0;
        if (c.layout == "time" && c.spacingDeg > 0)
            c.sampleRateHz = run.capture.feed / 60.0 / run.radius / kDeg / c.spacingDeg;
        c.feedFromData = r.summary.feedEstimate;
        c.relativeLength = run.capture.relativeLength;
        c.date = !file.date.empty() ? file.date : run.date;
        c.instrument = !file.instrument.empty() ? file.instrument : run.instrument;
        c.operatorName = !file.operatorName.empty() ? file.operatorName : run.operatorName;
        out.runs.push_back(std::move(r));
    }

    // Squareness → the deviation set, through the machine's own kinematics.
    std::map<std::string, LinearCircleDeviation> byName;
    std::map<std::string, double> weight;
    for (size_t i = 0; i < runs.size(); ++i) {
        const LinearCircleRun& run = runs[i];
        const LinearCircleRunResult& r = out.runs[i];
        const std::string iso = lcSquarenessName(m, run.plane);
        const std::string pname = fmt::format("squareness {}", linearPlaneName(run.plane));
        const LinearCircleParameter* p = lcParameter(r.fit, pname);
        if (m.deviationIndex(iso) < 0) {
            out.notes.push_back(fmt::format("run '{}': machine '{}' has no deviation {}: the {} is reported only", run.name,
                                            m.name, iso, pname));
            continue;
        }
        if (!p || !p->identified) {
            out.notes.push_back(fmt::format("run '{}': {} is not identified (one direction only: confounded with the servo "
                                            "mismatch); {} not written from it",
                                            run.name, pname, iso));
            continue;
        }
        DeviationSet unit(m);
        unit.set(iso, kArcsec);
        LinearCircleRun nominal = run;
        nominal.capture.overshootDeg = 0;
        LinearCircleSettings settings = base;
        settings.cyclicPitch = run.cyclicPitch;
        const std::vector<LinearCirclePass> sim = lcModelPasses(nominal, simulateLinearCircle(Kinematics(m, unit), nominal));
        const LinearCircleFit f = identifyLinearCircle(run.circle(), sim, settings);
        const double s = f.values.squareness;  // µm/m per arcsec
        if (!(std::abs(s) > 1e-3)) {
            out.notes.push_back(fmt::format("run '{}': {} does not change the squareness this circle sees ({:.3g} µm/m per "
                                            "arcsec); not written",
                                            run.name, iso, s));
            continue;
        }
        LinearCircleDeviation& d = byName[iso];
        d.name = iso;
        d.perArcsec = s;
        const double v = p->value / s, sd = std::abs(p->stddev / s);
        const double w = sd > 0 ? 1.0 / (sd * sd) : 1e30;
        d.value = (d.value * weight[iso] + v * w) / (weight[iso] + w);
        weight[iso] += w;
        d.stddev = 1.0 / std::sqrt(weight[iso]);
        const double half = std::abs(p->upper95 - p->lower95) / 2 / std::abs(s);
        d.lower95 = d.runs.empty() ? v - half : std::min(d.lower95, d.value - half);
        d.upper95 = d.runs.empty() ? v + half : std::max(d.upper95, d.value + half);
        d.runs.push_back(run.name);
    }
    for (auto& [name, d] : byName) {
        if (d.runs.size() > 1) {  // combined: the interval from the combined σ with the normal quantile
            d.lower95 = d.value - 1.96 * d.stddev;
            d.upper95 = d.value + 1.96 * d.stddev;
        }
        out.deviations.set(name, d.value * kArcsec);
        out.written.push_back(d);
    }
    // Backlash → the reversal value of each axis (LinearCircleReversal: B = −b), inverse-variance mean of the steps.
    struct Step {
        double value, stddev, half;
        std::string from;
    };
    std::map<char, std::vector<Step>> steps;
    for (size_t i = 0; i < runs.size(); ++i)
        for (const char axis : linearPlaneAxes(runs[i].plane))
            for (const char* end : {"+", "-"}) {
                const std::string pname = fmt::format("backlash {}{}", axis, end);
                const LinearCircleParameter* p = lcParameter(out.runs[i].fit, pname);
                if (!p || !p->identified || !std::isfinite(p->value)) continue;
                steps[axis].push_back({p->value, p->stddev, std::abs(p->upper95 - p->lower95) / 2,
                                       fmt::format("{}: {}", runs[i].name, pname)});
            }
    for (const auto& [axis, list] : steps) {
        LinearCircleReversal rv;
        rv.axis = std::string(1, axis);
        double sw = 0, swv = 0, lo = 0, hi = 0;
        for (const Step& st : list) {
            const double w = st.stddev > 0 ? 1.0 / (st.stddev * st.stddev) : 1e30;
            sw += w;
            swv += w * st.value;
            rv.from.push_back(st.from);
        }
        const double b = swv / sw;
        rv.value = -b;
        rv.stddev = 1.0 / std::sqrt(sw);
        if (list.size() == 1) {  // one step: its own interval (Student t of the fit)
            lo = -list[0].value - list[0].half;
            hi = -list[0].value + list[0].half;
        } else {  // combined: the combined σ with the normal quantile
            lo = rv.value - 1.96 * rv.stddev;
            hi = rv.value + 1.96 * rv.stddev;
        }
        rv.lower95 = lo;
        rv.upper95 = hi;
        if (m.axisIndex(rv.axis) < 0) continue;  // the run's validation already needs the axis
        out.deviations.setReversal(rv.axis, rv.value * kUm);
        double spread = 0;
        for (const Step& st : list) spread = std::max(spread, std::abs(st.value - b));
        if (list.size() > 1)
            out.notes.push_back(fmt::format("B{} = {:.3f} um from {} backlash steps ({}); the steps differ from their mean by up "
                                            "to {:.3f} um, which one reversal value cannot hold",
                                            rv.axis, rv.value, list.size(), fmt::join(rv.from, ", "), spread));
        out.reversals.push_back(std::move(rv));
    }
    out.notes.push_back("scale mismatch, straightness, reversal spikes, lateral play, cyclic error and servo mismatch have "
                        "no place in the deviation set: they are reported, not written");
    return out;
}

}  // namespace cnccomp
