// The rotary-axis and ball-bar identification methods of the registry (identify_registry.hpp), one per kind of plan
// (identification/plan_method.hpp): each runs either the least-squares solution on the exact model or the paper's
// formulas on the plan's captures read once, writes its tables into the summary and returns the deviation set (and
// the report of a least-squares solution). Nothing is printed or written here.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <ostream>
#include <set>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "cnccomp/closed_form.hpp"
#include "cnccomp/error.hpp"
#include "cnccomp/identification/dbb5_observation.hpp"
#include "cnccomp/identification/eccentricity_observation.hpp"
#include "cnccomp/identification/lsq.hpp"
#include "cnccomp/identification/staged_fit.hpp"
#include "cnccomp/identification/parameters.hpp"
#include "cnccomp/identification/plan_observations.hpp"
#include "cnccomp/identification/rtest_axis_tables.hpp"
#include "cnccomp/identification/rtest_location_fits.hpp"
#include "cnccomp/identification/sphere_probe.hpp"
#include "cnccomp/identification/dbb5_component_errors.hpp"
#include "cnccomp/identification/dbb5_cone_frustum.hpp"
#include "cnccomp/identification/dbb5_location_errors.hpp"
#include "cnccomp/identification/dbb5_xyc_test.hpp"
#include "cnccomp/identification/tilting_head_errors.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/eccentricity_csv.hpp"
#include "cnccomp/io/text_util.hpp"
#include "app/identify_registry.hpp"

namespace cnccomp::app {
using namespace cnccomp::identification;
using namespace cnccomp::io;
using namespace cnccomp::measurement;
namespace {

/// The ball-bar traces of the plan's <run> elements, as read once.
std::vector<BallbarTrace> ballbarTraces(const MethodRequest& r) {
    std::vector<BallbarTrace> out;
    for (const MeasuredTrace& t : r.data->ballbar) out.push_back(t.trace);
    return out;
}

/// --params names deviations of the machine (checked before any file is read; engineOptions parses them again).
void checkParams(const MethodRequest& r) {
    if (!r.params.empty()) parseDeviationList(*r.machine, r.params);
}

void requireTraces(const MethodRequest& r) {
    if (r.traces.empty()) throw ModelError("give the measured runs with --traces DIR (one <run>.csv per run of the plan)");
    if (!r.eccentricities.empty())
        throw ModelError(fmt::format("--eccentricities is for the ball-bar formulas only; this plan is '{}'",
                                     planMethodName(r.kind)));
}

/// The outer (tilting) and inner (table) rotary axes of a cradle method.
std::pair<std::string, std::string> cradleAxes(const MethodRequest& r) {
    auto axes = tableRotaryAxes(*r.machine);
    if (!r.outer.empty()) axes.first = r.outer;
    if (!r.inner.empty()) axes.second = r.inner;
    if (axes.first.empty() || axes.second.empty())
        throw ModelError(fmt::format("machine '{}' has no pair of rotary table axes; name them with --outer and --inner",
                                     r.machine->name));
    return axes;
}

/// The eleven location and squareness errors of a table-table machine (R-test and DBB5 methods).
std::vector<int> elevenErrors(const MachineModel& m, const std::string& outer, const std::string& inner) {
    const DeviationSet d(m);
    std::vector<int> out;
    for (const std::string& n : {std::string("EC0Y"), std::string("EB0Z"), std::string("EA0Z"), "EY0" + outer,
                                 "EZ0" + outer, "EB0" + outer, "EC0" + outer, "EX0" + inner, "EY0" + inner,
                                 "EA0" + inner, "EB0" + inner})
        out.push_back(d.require(n));
    std::sort(out.begin(), out.end());
    return out;
}

/// The solver's settings of a request (no file read).
IdentifyOptions solverOptions(const MethodRequest& r) {
    IdentifyOptions io;
    io.solver = r.solver;
    io.maxIterations = r.maxIterations;
    io.rankTolerance = r.rankTolerance;
    io.monteCarlo = r.monteCarlo;
    io.seed = r.seed;
    io.staged = !r.oneStage;
    io.bounds = r.parsedBounds;
    return io;
}

IdentifyOptions engineOptions(const MethodRequest& r, std::vector<int> defaults) {
    const MachineModel& m = *r.machine;
    IdentifyOptions io = solverOptions(r);
    io.deviations = r.params.empty() ? std::move(defaults) : parseDeviationList(m, r.params);
    if (io.deviations.empty())
        for (int i = 0; i < static_cast<int>(m.deviations.size()); ++i) io.deviations.push_back(i);
    if (!r.start.empty()) io.start = readDeviationCsv(r.start, m);
    if (r.plan && std::isfinite(r.plan->noiseUm)) io.statedNoise = r.plan->noiseUm * kUm;
    return io;
}

void noEngineOptions(const MethodRequest& r, const char* why) {
    if (!r.params.empty() || !r.bounds.empty() || !r.start.empty() || r.monteCarlo > 0 || r.solver != SolverChoice{})
        throw ModelError(fmt::format("--params, --bounds, --start, --monte-carlo and --solver do not apply: {}", why));
}

int refineOr(const MethodRequest& r, int fallback) {
    const int n = r.refine < 0 ? fallback : r.refine;
    if (n > 20) throw ModelError("--refine takes 0..20 passes");
    return n;
}

// ---- least squares on every sample of every run (ball-bar, mixed, R-test location, DBB5 plans)

IdentificationSummary generalLeastSquares(const MethodRequest& r, std::vector<int> defaults, const std::string& what) {
    const MachineModel& m = *r.machine;
    const MeasurementPlan& plan = *r.plan;
    std::optional<MeasuredRuns> measured;
    Observations obs;
    if (r.observe == Observe::Eccentricity) {
        obs = eccentricityObservations(m, plan.runs, ballbarTraces(r));
    } else {
        measured = measuredObservations(m, plan, *r.data);  // ball-bar files imported and checked against their runs
        obs = std::move(measured->observations);
    }
    const IdentifyOptions io = engineOptions(r, std::move(defaults));
    IdentificationResult res = identifyStaged(m, obs, io);
    const auto identified = std::count_if(io.deviations.begin(), io.deviations.end(),
                                          [&](int i) { return res.deviations.present[static_cast<size_t>(i)] != 0; });
    IdentificationSummary out{res.deviations, res.report, {}, "", std::nullopt, std::nullopt};
    if (measured) {
        measured->observations = std::move(obs);
        out.measured = std::move(measured);
    }
    out.result = std::move(res);
    const IdentificationReport& rep = out.result->report;
    out.summary = fmt::format("identified {} of {} requested deviations of '{}' ({}, least squares on {} samples of {} runs)",
                              identified, io.deviations.size(), m.name, what, rep.observations, plan.runCount());
    return out;
}

// ---- ball-bar formulas (eccentricities)

void checkBallbarFormulas(const MethodRequest& r) {
    noEngineOptions(r, "the eccentricity formulas have no free unknowns");
    if (!r.eccentricities.empty()) {
        if (!r.traces.empty()) throw ModelError("give either --eccentricities or --traces with --plan, not both");
    } else if (r.traces.empty() || !r.plan) {
        throw ModelError("the ball-bar formulas need --eccentricities E.csv, or --traces DIR with --plan P.xml");
    }
}

IdentificationSummary ballbarFormulas(const MethodRequest& r) {
    const MachineModel& m = *r.machine;
    const std::vector<EccentricityRow> rows = !r.eccentricities.empty()
                                                  ? readEccentricityCsv(r.eccentricities)
                                                  : eccentricitiesFromTraces(m, r.plan->runs, ballbarTraces(r));
    const int refine = refineOr(r, 3);
    IdentificationSummary out{identifyClosedForm(m, rows, {refine, 1.0}), std::nullopt, {}, "", std::nullopt, std::nullopt};
    out.summary = fmt::format("identified {} deviations of '{}' (ball-bar eccentricity formulas (17)-(28), {} refinement "
                              "passes on the exact model)",
                              std::count(out.deviations.present.begin(), out.deviations.present.end(), 1), m.name, refine);
    return out;
}

// ---- tilting head from absolute ball-bar patterns

void checkHeadPatterns(const MethodRequest& r) {
    requireTraces(r);
    noEngineOptions(r, "the head-pattern method identifies the head axis' error tables and its orientation");
}

IdentificationSummary headPatterns(const MethodRequest& r) {
    const MachineModel& m = *r.machine;
    const std::vector<BallbarTrace>& traces = r.data->absolute;
    const TiltingHeadResult f = tiltingHeadFormulas(r.plan->absoluteRuns, traces);
    IdentificationSummary out{DeviationSet(m), std::nullopt, {}, "", std::nullopt, std::nullopt};
    std::vector<TiltingHeadAngle> rows;
    if (r.formulas) {
        out.deviations = tiltingHeadDeviations(m, f);
        rows = f.angles;
        out.summary = fmt::format("head patterns, formulas (7), (9), (16), (21) with tool lengths L1 = {:g} mm, L2 = {:g} mm",
                                  f.L1, f.L2);
    } else {
        const TiltingHeadLsq ls = tiltingHeadLeastSquares(m, r.plan->absoluteRuns, traces);
        out.deviations = ls.deviations;
        for (const std::string& w : ls.engine.report.warnings) r.say("warning: {}\n", w);
        for (const TiltingHeadAngle& a : f.angles) {
            TiltingHeadAngle h;
            h.angleDeg = a.angleDeg;
            double* v[] = {&h.dx, &h.dy, &h.dz, &h.ex, &h.ey};
            const char* c[] = {"EX", "EY", "EZ", "EA", "EB"};
            for (int i = 0; i < 5; ++i) {
                const DeviationDef& def = m.deviations[static_cast<size_t>(out.deviations.require(c[i] + f.headAxis))];
                *v[i] = def.basis.evaluate(a.angleDeg * kDeg, out.deviations.values.data() + def.offset, false);
            }
            rows.push_back(h);
        }
        out.summary = fmt::format("head patterns, least squares on {} samples (rank {} of {}, {}), split into the head "
                                  "axis' orientation and its tables with the gauge of formula (9)",
                                  ls.engine.report.observations, ls.engine.report.rank, ls.engine.report.unknowns,
                                  ls.engine.report.termination);
    }
    r.say("{:>8} {:>10} {:>10} {:>10} {:>12} {:>12}   (errors of {} over its angle, link values)\n", "deg",
          "dx um", "dy um", "dz um", "ex arcsec", "ey arcsec", f.headAxis);
    for (const TiltingHeadAngle& h : rows)
        r.say("{:8.2f} {:10.4f} {:10.4f} {:10.4f} {:12.4f} {:12.4f}\n", h.angleDeg, h.dx / kUm, h.dy / kUm,
              h.dz / kUm, h.ex / kArcsec, h.ey / kArcsec);
    const std::string head = f.headAxis;
    out.extras.push_back({"--angles-out", [rows, head](std::ostream& o) {
                              o << head << "_deg,dx_um,dy_um,dz_um,ex_arcsec,ey_arcsec\n";
                              for (const TiltingHeadAngle& h : rows)
                                  o << fmt::format("{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f}\n", h.angleDeg, h.dx / kUm,
                                                   h.dy / kUm, h.dz / kUm, h.ex / kArcsec, h.ey / kArcsec);
                          }});
    return out;
}

// ---- R-test: location errors and squareness

void checkRtestLocation(const MethodRequest& r) {
    requireTraces(r);
    cradleAxes(r);
    if (r.formulas) noEngineOptions(r, "the R-test fits identify the eleven location and squareness errors");
    else checkParams(r);
}

IdentificationSummary rtestLocation(const MethodRequest& r) {
    const MachineModel& m = *r.machine;
    const auto [outer, inner] = cradleAxes(r);
    const std::vector<RtestTrace>& traces = r.data->rtest;
    IdentificationSummary out{DeviationSet(m), std::nullopt, {}, "", std::nullopt, std::nullopt};
    if (r.formulas) {
        const RtestLocationResult f = rtestLocationFits(m, r.plan->rtestRuns, traces, {outer, inner, refineOr(r, 4)});
        out.deviations = f.deviations;
        r.say("fits: {} circle centre ({:.4f}, {:.4f}, {:.4f}) mm r = {:.4f} mm; {} circle centre ({:.4f}, {:.4f}, "
              "{:.4f}) mm r = {:.4f} mm\n",
              outer, f.outerCircle.center.x(), f.outerCircle.center.y(), f.outerCircle.center.z(),
              f.outerCircle.radius, inner, f.innerCircle.center.x(), f.innerCircle.center.y(),
              f.innerCircle.center.z(), f.innerCircle.radius);
        r.say("eq. (2): C_XY = {:.3f} um/m, C_YZ = {:.3f} um/m, C_ZX = {:.3f} um/m ({} tilted ±{:g} deg)\n",
              f.cXY * 1e6, f.cYZ * 1e6, f.cZX * 1e6, outer, f.phiDeg);
        out.summary = fmt::format("R-test location fits (circle, line and ellipse fits, eq. (2)), {} refinement steps on "
                                  "the exact model",
                                  f.refine);
    } else {
        out = generalLeastSquares(r, elevenErrors(m, outer, inner), "R-test location and squareness");
    }
    if (!r.volumetricRun.empty()) {
        const auto& runs = r.plan->rtestRuns;
        const auto it = std::find_if(runs.begin(), runs.end(), [&](const RtestRun& x) { return x.name == r.volumetricRun; });
        if (it == runs.end()) throw ModelError(fmt::format("the plan has no R-test run '{}'", r.volumetricRun));
        const size_t i = static_cast<size_t>(it - runs.begin());
        const VolumetricAlongRun v = volumetricErrorAlongRun(m, out.deviations, *it, traces[i]);
        r.say("volumetric error along '{}': measured RMS {:.4f} um, model RMS residual {:.4f} um, max {:.4f} um\n",
              r.volumetricRun, v.rmsMeasured / kUm, v.rmsResidual / kUm, v.maxResidual / kUm);
        out.extras.push_back({"--volumetric-out", [v](std::ostream& o) {
                                  o << "pose,meas_dx_um,meas_dy_um,meas_dz_um,calc_dx_um,calc_dy_um,calc_dz_um,delta_um\n";
                                  for (size_t k = 0; k < v.measured.size(); ++k) {
                                      const Vec3 a = v.measured[k] / kUm, b = v.predicted[k] / kUm;
                                      o << fmt::format("{},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f}\n", k + 1, a.x(),
                                                       a.y(), a.z(), b.x(), b.y(), b.z(), (a - b).norm());
                                  }
                              }});
    }
    return out;
}

// ---- R-test: six errors of each rotary axis over angle

/// Largest |value| (and |value − truth|) of every component table of the two axes.
void printTables(const MethodRequest& r, const DeviationSet& d, const std::vector<std::string>& axes) {
    const MachineModel& m = d.machine();
    r.say("{:<6} {:<8} {:>5} {:>12}  {}\n", "table", "alias", "nodes", "max |value|", "unit");
    for (const std::string& ax : axes)
        for (const char* c : {"EX", "EY", "EZ", "EA", "EB", "EC"}) {
            const int i = m.deviationIndex(c + ax);
            if (i < 0) continue;
            const DeviationDef& def = m.deviations[static_cast<size_t>(i)];
            const double s = def.isAngle() ? kArcsec : kUm;
            double vmax = 0;
            for (int k = 0; k < def.size(); ++k) vmax = std::max(vmax, std::abs(d.values[def.offset + k]) / s);
            r.say("{:<6} {:<8} {:>5} {:12.4f}  {}\n", def.name, def.alias, def.size(), vmax,
                  def.isAngle() ? "arcsec" : "um");
        }
}

void checkRtestTables(const MethodRequest& r) {
    requireTraces(r);
    noEngineOptions(r, "the R-test tables method identifies the six error tables of both rotary axes");
    cradleAxes(r);
}

IdentificationSummary rtestTables(const MethodRequest& r) {
    const MachineModel& m = *r.machine;
    const auto [outer, inner] = cradleAxes(r);
    const std::vector<RtestTrace>& traces = r.data->rtest;
    IdentificationSummary out{DeviationSet(m), std::nullopt, {}, "", std::nullopt, std::nullopt};
    if (r.formulas) {
        std::vector<AxisErrors> per;
        out.deviations = cradleTablesPerAngle(m, outer, inner, r.plan->rtestRuns, traces, &per);
        for (const AxisErrors& a : per)
            r.say("eq. (1)-(7) per angle: axis {} at {} angles, worst fit residual {:.5f} um\n", a.axis,
                  a.samples.size(),
                  std::max_element(a.samples.begin(), a.samples.end(), [](auto& x, auto& y) { return x.rms < y.rms; })->rms / kUm);
        out.summary = fmt::format("R-test tables of {} and {}, per-angle formulas (1)-(7) ({} first)", outer, inner, outer);
    } else {
        const CradleLsq ls = cradleLeastSquares(m, outer, inner, r.plan->rtestRuns, traces);
        out.deviations = ls.deviations;
        for (const std::string& w : ls.report.warnings) r.say("warning: {}\n", w);
        out.summary = fmt::format("R-test tables of {} and {}, least squares: rank {} of {} ({} unobservable directions, the "
                                  "constant transform between the {} and {} frames, fixed by '{} errors = 0 at {} = 0'), {}",
                                  outer, inner, ls.report.rank, ls.report.unknowns, ls.report.unobservable.size(), outer,
                                  inner, inner, inner, ls.report.termination);
    }
    printTables(r, out.deviations, {outer, inner});
    return out;
}

// ---- DBB5 (Ibaraki et al., "Identification of motion error sources on five-axis machine tools by ball-bar
//      measurements (1st report)")

void checkDbb5(const MethodRequest& r) {
    requireTraces(r);
    const MachineModel& m = *r.machine;
    const std::vector<Dbb5Run>& runs = r.plan->dbb5Runs;
    // Only circles of the linear axes on a machine without a pair of table axes: the route of <circle> runs fits them.
    if (tableRotaryAxes(m).first.empty() && r.outer.empty() &&
        std::all_of(runs.begin(), runs.end(), [](const Dbb5Run& x) { return x.kind == Dbb5Run::Kind::LinearCircle; }))
        throw ModelError(fmt::format("the plan's DBB5 runs are circles of the linear axes, and machine '{}' has no tilting "
                                     "rotary table for the DBB5 method: write them as <circle> runs (plane, centre, radius, "
                                     "arc; README \"Linear-axis circles (ISO 230-4)\"), whose identification needs no rotary "
                                     "axis and estimates the bar's centring offset",
                                     m.name));
    if (r.formulas) noEngineOptions(r, "the DBB5 formulas identify the eleven location and squareness errors");
    else checkParams(r);
}

IdentificationSummary dbb5(const MethodRequest& r) {
    const MachineModel& m = *r.machine;
    const std::vector<Dbb5Run>& runs = r.plan->dbb5Runs;
    const std::vector<BallbarTrace>& traces = r.data->dbb5;
    r.say("{:<14} {:>8} {:>16} {:>18} {:>10}  (ISO 230-4)\n", "run", "samples", "circularity um",
          "mean radial err um", "b2 um");
    std::vector<CircularTestResult> iso;
    for (size_t i = 0; i < traces.size(); ++i) {
        iso.push_back(evaluateCircularTest(traces[i], runs[i].LB));
        r.say("{:<14} {:>8} {:16.4f} {:18.4f} {:10.4f}\n", runs[i].name, iso.back().samples,
              iso.back().circularity / kUm, iso.back().meanRadialError / kUm, iso.back().b2 / kUm);
    }
    const Dbb5LocationOptions lo{r.outer, r.inner, refineOr(r, 4)};
    IdentificationSummary out{DeviationSet(m), std::nullopt, {}, "", std::nullopt, std::nullopt};
    if (r.formulas) {
        const Dbb5LocationResult f = dbb5LocationErrors(m, runs, traces, lo);
        out.deviations = f.deviations;
        r.say("plain formulas, the paper's definitions (relative to the machine axes):\n");
        for (const Dbb5FormulaValue& v : f.formulas)
            r.say("  {:<18} {:>10.4f} {:<6}  {}\n", v.name, v.value / (v.angle ? kArcsec : kUm),
                  v.angle ? "arcsec" : "um", v.definition);
        out.summary = fmt::format("DBB5 formulas (1)-(3), (6)-(7) and the elliptic term of the linear circles, {} "
                                  "refinement steps on the exact model{}",
                                  f.refine, f.refine > 0 ? "" : " (plain formulas converted to the model's definitions)");
    } else {
        std::vector<int> eleven = dbb5LocationDeviations(m, lo);
        std::sort(eleven.begin(), eleven.end());
        out = generalLeastSquares(r, std::move(eleven), "DBB5 location and squareness");
    }
    if (r.components) {
        const std::string inner = dbb5TableAxes(m, lo).second;
        const Dbb5ComponentProfile p = dbb5ComponentProfile(m, runs, traces, out.deviations, inner);
        out.deviations = dbb5ComponentTables(m, p, out.deviations);
        r.say("component errors of {} from {} (bed frame, relative to the average line; tilts: {}, axial: {}) "
              "-> the model's tables\n",
              inner, fmt::join(p.runs, ", "), p.tilts ? "yes" : "no", p.axial ? "yes" : "no");
        out.extras.push_back({"--profile-out", [p](std::ostream& o) {
                                  o << "angle_deg,dx_um,dy_um,dz_um,ex_arcsec,ey_arcsec,ez_arcsec\n";
                                  for (size_t i = 0; i < p.angleDeg.size(); ++i)
                                      o << fmt::format("{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f}\n", p.angleDeg[i],
                                                       p.translation[i].x() / kUm, p.translation[i].y() / kUm,
                                                       p.translation[i].z() / kUm, p.tilt[i].x() / kArcsec,
                                                       p.tilt[i].y() / kArcsec, p.tilt[i].z() / kArcsec);
                              }});
    }
    for (size_t i = 0; i < runs.size(); ++i) {
        const Dbb5Run& run = runs[i];
        if (isDbb5XycTest(m, run)) {
            const Dbb5XycResult x = evaluateDbb5XycTest(m, run, traces[i]);
            r.say("XYC test {}: centre offset ({:.4f}, {:.4f}) um at R = {:g} mm -> {} {:.4f} arcsec, {} {:.4f} arcsec "
                  "(eq. (4)-(5), relative to the plane of motion)\n",
                  run.name, x.centre[0] / kUm, x.centre[1] / kUm, x.radius,
                  fmt::format("E{}0{}", "ABC"[x.second], run.axis), x.rotation[x.second] / kArcsec,
                  fmt::format("E{}0{}", "ABC"[x.first], run.axis), x.rotation[x.first] / kArcsec);
        } else if (run.kind == Dbb5Run::Kind::ConeFrustum) {
            const Dbb5ConeEvaluation c = evaluateDbb5ConeRun(m, run, traces[i], &out.deviations);
            r.say("cone frustum {}: circularity {:.4f} um; measured - predicted by the identified errors: rms {:.4f} "
                  "um, max {:.4f} um ({})\n",
                  run.name, c.iso.circularity / kUm, c.rmsDifference / kUm, c.maxDifference / kUm,
                  r.formulas ? "not used by the formulas: an independent check"
                             : "a run of the fit, not an independent check");
        }
    }
    std::vector<std::string> names;
    for (const Dbb5Run& run : runs) names.push_back(run.name);
    out.extras.push_back({"--iso-out", [iso, names](std::ostream& o) {
                              o << "run,samples,circularity_um,mean_radial_error_um,radial_max_um,radial_min_um,b2_um\n";
                              for (size_t i = 0; i < iso.size(); ++i)
                                  o << fmt::format("{},{},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f}\n", names[i], iso[i].samples,
                                                   iso[i].circularity / kUm, iso[i].meanRadialError / kUm,
                                                   iso[i].radialMax / kUm, iso[i].radialMin / kUm, iso[i].b2 / kUm);
                          }});
    return out;
}


// ---- touch probe on a calibration sphere

/// Default unknowns of a sphere plan: the location errors of every rotary axis the plan turns, except the two no
/// sphere centre can show: the position along the axis' own line and its zero position (rotation about itself); and
/// the squareness of the linear axes (rotations of linear-axis links), which the stylus' travel over the poses
/// determines (the sample plan: about 1″ for σ = 1 µm per touch). For a table-table A/C machine: EY0A EZ0A EB0A EC0A
/// EX0C EY0C EA0C EB0C and EC0Y EB0Z EA0Z.
std::vector<int> sphereDefaults(const MachineModel& m, const Observations& obs) {
    std::set<std::string> turning;
    for (const auto& o : obs)
        for (const std::string& a : o->turningAxes()) turning.insert(a);
    std::vector<int> out;
    for (int i = 0; i < static_cast<int>(m.deviations.size()); ++i) {
        const DeviationDef& d = m.deviations[static_cast<size_t>(i)];
        if (d.kind != DeviationKind::Location) continue;
        const Link* l = &m.chain(d.side).links[static_cast<size_t>(d.link)];
        if (l->kind == AxisKind::Linear && d.isAngle()) {
            out.push_back(i);
            continue;
        }
        if (l->kind != AxisKind::Rotary || !turning.count(l->name)) continue;
        const Vec3 axis = l->direction.normalized();
        const int c = d.component;  // 0..2 translation x y z, 3..5 rotation a b c
        if (std::abs(axis[c % 3]) > 0.999) continue;  // along the axis' line or about it
        out.push_back(i);
    }
    return out;
}

void checkSphere(const MethodRequest& r) {
    if (r.traces.empty())
        throw ModelError(fmt::format("give the folder of the probe result file with --traces DIR (DIR/{})", r.probeLog));
    if (r.formulas) throw ModelError("the sphere method has no paper's formulas: use --method least-squares");
    sphereCommands(*r.machine, r.plan->sphereRuns);  // the machine makes every pose
    checkParams(r);
}

IdentificationSummary sphereProbe(const MethodRequest& r) {
    const MachineModel& m = *r.machine;
    const SpherePlanCommands cmds = sphereCommands(m, r.plan->sphereRuns);
    const ProbeLog& log = *r.data->probes;
    Observations obs = sphereObservations(m, cmds, log);
    r.say("{:<16} {:>6} {:>8} {:>22}  (sphere centres fitted with the known radius)\n", "run", "poses", "touches",
          "worst fit rms um (pose)");
    for (size_t i = 0; i < obs.size(); ++i) {
        const auto& so = static_cast<const SphereObservation&>(*obs[i]);
        const auto& rms = so.fitRms();
        const auto w = std::max_element(rms.begin(), rms.end());
        r.say("{:<16} {:>6} {:>8} {:>16.4f} ({:>3})\n", so.runName(), rms.size(),
              rms.size() * static_cast<size_t>(cmds.runs[i].run.touchesPerPose()), *w / kUm,
              cmds.runs[i].poses[static_cast<size_t>(w - rms.begin())].planPose);
    }
    const IdentifyOptions io = engineOptions(r, sphereDefaults(m, obs));
    IdentificationResult res = cnccomp::identification::identify(m, obs, io);
    const auto identified = std::count_if(io.deviations.begin(), io.deviations.end(),
                                          [&](int i) { return res.deviations.present[static_cast<size_t>(i)] != 0; });
    IdentificationSummary out{res.deviations, res.report, {}, "", std::nullopt, std::nullopt};
    out.result = std::move(res);
    out.summary = fmt::format("identified {} of {} requested deviations of '{}' (sphere probing, least squares on the "
                              "centres of {} poses, {} touches)",
                              identified, io.deviations.size(), m.name, cmds.poseCount(), log.touches.size());
    return out;
}

// ---- what each method reads, and the registry's entries

MeasurementKinds only(bool MeasurementKinds::*kind) {
    MeasurementKinds k;
    k.*kind = true;
    return k;
}

void checkBallbar(const MethodRequest& r) {
    if (r.formulas) return checkBallbarFormulas(r);
    if (!r.eccentricities.empty())
        throw ModelError("least squares works on the raw traces: give --traces DIR and --plan P.xml (an "
                         "eccentricity table is for --method formulas)");
    requireTraces(r);
    checkParams(r);
}

MeasurementKinds ballbarReads(const MethodRequest& r) {
    if (r.formulas) return r.eccentricities.empty() ? only(&MeasurementKinds::ballbar) : MeasurementKinds{};
    return r.observe == Observe::Eccentricity ? only(&MeasurementKinds::ballbar) : MeasurementKinds::observed();
}

IdentificationSummary ballbar(const MethodRequest& r) {
    return r.formulas ? ballbarFormulas(r) : generalLeastSquares(r, {}, "ball-bar runs");
}

void checkMixed(const MethodRequest& r) {
    if (r.formulas)
        throw ModelError("the plan has runs of several kinds: no paper's formulas take them together; it fits "
                         "--method least-squares");
    requireTraces(r);
    checkParams(r);
}

MeasurementKinds observed(const MethodRequest&) { return MeasurementKinds::observed(); }

IdentificationSummary mixed(const MethodRequest& r) { return generalLeastSquares(r, {}, "runs of several kinds"); }

MeasurementKinds headReads(const MethodRequest&) { return only(&MeasurementKinds::absolute); }
MeasurementKinds rtestReads(const MethodRequest&) { return only(&MeasurementKinds::rtest); }
MeasurementKinds sphereReads(const MethodRequest&) { return only(&MeasurementKinds::probes); }
/// The formulas read their own runs; least squares every run of the plan.
MeasurementKinds rtestLocationReads(const MethodRequest& r) {
    return r.formulas ? only(&MeasurementKinds::rtest) : MeasurementKinds::observed();
}
MeasurementKinds dbb5Reads(const MethodRequest& r) {
    return r.formulas ? only(&MeasurementKinds::dbb5) : MeasurementKinds::observed();
}

}  // namespace

std::vector<IdentificationMethod> rotaryAxisMethods() {
    const auto entry = [](PlanMethod kind, auto reads, auto check, auto run) {
        return IdentificationMethod{planMethodName(kind), {kind}, planMethodMeasures(kind), reads, check, run};
    };
    return {entry(PlanMethod::Ballbar, ballbarReads, checkBallbar, ballbar),
            entry(PlanMethod::Mixed, observed, checkMixed, mixed),
            entry(PlanMethod::HeadPatterns, headReads, checkHeadPatterns, headPatterns),
            entry(PlanMethod::RtestLocation, rtestLocationReads, checkRtestLocation, rtestLocation),
            entry(PlanMethod::RtestTables, rtestReads, checkRtestTables, rtestTables),
            entry(PlanMethod::Dbb5, dbb5Reads, checkDbb5, dbb5),
            entry(PlanMethod::Sphere, sphereReads, checkSphere, sphereProbe)};
}

}  // namespace cnccomp::app
