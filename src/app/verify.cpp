#include "app/verify.hpp"

#include "app/verify_sphere.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/identification/rtest_run.hpp"
#include "cnccomp/inverse_kinematics.hpp"
#include "cnccomp/lost_motion.hpp"
#include "controllers/common/directional.hpp"
#include "controllers/common/evaluate.hpp"
#include "postproc/testprog/read_back.hpp"
#include "postproc/testprog/test_program.hpp"

namespace cnccomp::app {
using namespace cnccomp::identification;
using namespace cnccomp::measurement;

namespace {

class IdealCompensation final : public controllers::AppliedCompensation, public controllers::common::DirectionalCompensation {
public:
    IdealCompensation(const MachineModel& m, const DeviationSet& d) : nominal_(m), identified_(m, d), reversal_(d) {}
    AxisVector driveCommands(const AxisVector& q) const override { return driveCommandsForTool(q, 0.0); }
    AxisVector driveCommandsForTool(const AxisVector& q, double toolLength) const override {
        const Vec3 tip = nominal_.toolPoint(toolLength);
        const IkResult r = solveToolPose(identified_, toolPose(nominal_, q, tip), tip, q);
        return r.converged ? r.q : q;
    }
    /// The reversal values of the set taken off by direction (lost_motion.hpp: the slide reaches command + (B̄/2)·s, so
    /// the drive is sent −(B̄/2)·s further: what a controller's backlash β = −B̄ does, LinuxCNC ±BACKLASH/2).
    AxisVector driveCommandsMoving(const AxisVector& q, double toolLength, const AxisVector& motion) const override {
        const AxisVector drive = driveCommandsForTool(q, toolLength);
        return drive - (withLostMotion(reversal_, drive, motion) - drive);
    }

private:
    Kinematics nominal_, identified_;
    DeviationSet reversal_;
};

double span(const std::vector<double>& v) {
    if (v.empty()) return 0;
    const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
    return *hi - *lo;
}

std::string runType(const postproc::testprog::RunMotion& r) {
    if (r.ballbar) return std::string(testName(r.ballbar->test)) + (r.kind == postproc::testprog::RunKind::AbsoluteBallbar ? " absolute" : "");
    if (r.dbb5)
        return r.dbb5->kind == Dbb5Run::Kind::LinearCircle ? fmt::format("DBB5 {} circle", r.dbb5->plane)
                                                           : fmt::format("DBB5 {} circle", r.dbb5->axis);
    if (r.circle) return fmt::format("{} circle (ISO 230-4)", linearPlaneName(r.circle->plane));
    return "R-test";
}

double barLength(const postproc::testprog::RunMotion& r) {
    return r.ballbar ? r.ballbar->LB : r.dbb5 ? r.dbb5->LB : r.circle ? r.circle->radius : 0.0;
}

/// The commands of one run that reach the drives: setup and the samples of each pass.
struct RunCommands {
    AxisVector setup;
    std::vector<std::string> labels;
    std::vector<std::vector<double>> t;
    std::vector<std::vector<AxisVector>> q;
};

RunCommands samplesOf(const postproc::testprog::RunMotion& r, const postproc::testprog::ProgramCommands& p) {
    RunCommands c;
    c.setup = p.setup;
    for (const auto& pass : p.passes) {
        c.labels.push_back(pass.label);
        c.t.emplace_back();
        c.q.emplace_back();
        postproc::testprog::passSamples(r, pass, c.t.back(), c.q.back());
    }
    return c;
}

/// Largest excursion beyond an axis' travel along a pass (the commands as they reach the drives).
struct TravelCheck {
    int axis = -1, count = 0;
    double excess = 0, value = 0;
    void check(const MachineModel& m, const AxisVector& q) {
        bool out = false;
        for (int a = 0; a < m.axisCount(); ++a) {
            const Link& l = m.axisLink(a);
            const double e = std::max(l.min - q[a], q[a] - l.max);
            if (!(e > 1e-9) && std::isfinite(q[a])) continue;
            out = true;
            if (!(e <= excess)) excess = e, axis = a, value = q[a];
        }
        count += out;
    }
    std::string describe(const MachineModel& m) const {
        if (count == 0) return {};
        const Link& l = m.axisLink(axis);
        const double s = l.kind == AxisKind::Rotary ? 1 / kDeg : 1.0;
        const char* u = l.kind == AxisKind::Rotary ? "deg" : "mm";
        return fmt::format("{} reaches {:.4f} {} (travel {:g} .. {:g} {}) at {} command(s)", m.axisNames[axis], value * s, u,
                           l.min * s, l.max * s, u, count);
    }
};

/// The instrument's readings along one pass on machine k: ΔL of a bar ([MultiTasking] eq. (14); absolute bar: Ball 2 at its
/// nominal place, [FanWuLi]; DBB5, [IbarakiDBB5]), or the R-test displacement ([Moravek2019]).
void simulatePass(const Kinematics& k, const Kinematics& nominal, const postproc::testprog::RunMotion& r, const AxisVector& setup,
                  const AxisVector& nominalSetup, const std::vector<double>& t, const std::vector<AxisVector>& q,
                  BallbarTrace& trace, std::vector<Vec3>& displacement, TravelCheck& travel) {
    const MachineModel& m = k.machine();
    travel.check(m, setup);
    trace.angleDeg = t;
    trace.dL.assign(q.size(), 0.0);
    displacement.clear();
    if (r.rtest) {
        const Vec3 nest = k.toolPoint(r.rtest->nestLength), ball = r.rtest->ball + r.rtest->ballOffset;
        for (size_t i = 0; i < q.size(); ++i) {
            travel.check(m, q[i]);
            displacement.push_back(rtestDisplacement(k, q[i], ball, nest));
            trace.dL[i] = displacement.back().norm();
        }
        return;
    }
    Vec3 tool, ref;
    double LB = 0;
    if (r.ballbar) {
        const BallbarRun& b = *r.ballbar;
        tool = k.toolPoint(b.RB, b.toolBallOffset);
        LB = b.LB;
        ref = r.kind == postproc::testprog::RunKind::AbsoluteBallbar
                  ? nominal.toolPointInWorkpiece(nominalSetup, nominal.toolPoint(b.RB, b.toolBallOffset)) + b.workBallOffset
                  : k.toolPointInWorkpiece(setup, tool) + b.workBallOffset;  // eq. (11)–(13), (16)
    } else if (r.circle) {
        // ISO 230-4 circle of the linear axes (linear_circle_run.hpp): the pivot ball set under the tool ball at the
        // centre commands as they reach the drives, ΔL = |P(θ) − P(centre)| − R in the workpiece frame.
        tool = k.toolPoint(r.circle->toolLength);
        LB = r.circle->radius;
        ref = k.toolPointInWorkpiece(setup, tool);
    } else {
        tool = k.toolPoint(r.dbb5->toolLength);
        LB = r.dbb5->LB;
        ref = k.toolPointInWorkpiece(setup, tool);
    }
    for (size_t i = 0; i < q.size(); ++i) {
        travel.check(m, q[i]);
        trace.dL[i] = (k.toolPointInWorkpiece(q[i], tool) - ref).norm() - LB;  // eq. (14)
    }
}

double displacementSpan(const std::vector<Vec3>& d) {
    double s = 0;
    for (int c = 0; c < 3; ++c) {
        std::vector<double> v;
        for (const Vec3& x : d) v.push_back(x[c]);
        s = std::max(s, span(v));
    }
    return s;
}

/// ISO 230-4 figures and eccentricity of a ball-bar trace.
void analyse(const MachineModel& m, const postproc::testprog::RunMotion& r, const BallbarTrace& trace, CircularTestResult& iso,
             Vec3& eccentricity) {
    iso = evaluateCircularTest(trace, barLength(r));
    eccentricity = Vec3::Constant(NAN);
    if (r.ballbar) {
        eccentricity = traceEccentricity(m, *r.ballbar, trace);
    } else if (r.dbb5 && r.dbb5->kind == Dbb5Run::Kind::LinearCircle) {
        const auto [e1, e2] = r.dbb5->planeAxes();
        eccentricity = iso.center.x() * e1 + iso.center.y() * e2;
        for (int c = 0; c < 3; ++c)
            if (std::abs(e1[c]) + std::abs(e2[c]) == 0) eccentricity[c] = NAN;
    } else if (r.circle) {  // the least-squares centre along the plane's axes u, v (X Y Z components; the third NaN)
        const std::array<char, 2> ax = linearPlaneAxes(r.circle->plane);
        eccentricity[ax[0] - 'X'] = iso.center.x();
        eccentricity[ax[1] - 'X'] = iso.center.y();
    }
}

/// The grid over the box of the plan's commands (as the test programs write them) at the runs' tool lengths.
PlanWorkspace gridOver(const MachineModel& m, const std::vector<postproc::testprog::RunMotion>& motions,
                       const std::vector<RunCommands>& programmed, int perAxis) {
    const int n = m.axisCount();
    AxisVector lo = AxisVector::Constant(n, HUGE_VAL), hi = AxisVector::Constant(n, -HUGE_VAL);
    for (const RunCommands& c : programmed)
        for (const auto& pass : c.q)
            for (const AxisVector& q : pass) lo = lo.cwiseMin(q), hi = hi.cwiseMax(q);
    PlanWorkspace w;
    std::vector<int> idx(n, 0);
    const int k = std::max(1, perAxis);
    for (;;) {
        AxisVector q(n);
        for (int a = 0; a < n; ++a) q[a] = k == 1 || hi[a] <= lo[a] ? 0.5 * (lo[a] + hi[a]) : lo[a] + (hi[a] - lo[a]) * idx[a] / (k - 1);
        w.poses.push_back(q);
        int a = n - 1;
        for (; a >= 0; --a) {
            const int count = hi[a] > lo[a] ? k : 1;
            if (++idx[a] < count) break;
            idx[a] = 0;
        }
        if (a < 0) break;
    }
    for (const auto& r : motions)
        if (std::find(w.toolLengths.begin(), w.toolLengths.end(), r.toolLength) == w.toolLengths.end())
            w.toolLengths.push_back(r.toolLength);
    std::string box;
    for (int a = 0; a < n; ++a) {
        const bool rotary = m.axisLink(a).kind == AxisKind::Rotary;
        const double s = rotary ? 1 / kDeg : 1.0;
        box += fmt::format("{}{}={:g}:{:g}", box.empty() ? "" : " ", m.axisNames[a], lo[a] * s, hi[a] * s);
    }
    w.note = fmt::format("{} per axis over the commands of the plan's runs ({}), tool lengths", k, box);
    for (double L : w.toolLengths) w.note += fmt::format(" {:g}", L);
    w.note += " mm";
    return w;
}

void volumetric(const MachineModel& m, const DeviationSet& simulated, const controllers::AppliedCompensation& comp,
                const PlanWorkspace& w, VerifyVolumetric& v) {
    v.toolLengths = w.toolLengths;
    double sumBefore = 0, sumAfter = 0;
    for (double L : v.toolLengths) {
        const auto f = controllers::common::evaluateCompensation(m, simulated, comp, w.poses, L);
        v.maxBefore = std::max(v.maxBefore, f.maxBefore);
        v.maxAfter = std::max(v.maxAfter, f.maxAfter);
        v.tiltBefore = std::max(v.tiltBefore, f.maxAxisBefore);
        v.tiltAfter = std::max(v.tiltAfter, f.maxAxisAfter);
        sumBefore += f.rmsBefore * f.rmsBefore * f.points;
        sumAfter += f.rmsAfter * f.rmsAfter * f.points;
        v.points += f.points;
    }
    if (v.points > 0) {
        v.rmsBefore = std::sqrt(sumBefore / static_cast<double>(v.points));
        v.rmsAfter = std::sqrt(sumAfter / static_cast<double>(v.points));
    }
    v.available = true;
    v.note = w.note;
}

/// The commands of every run as the plan's test programs write them (generated in memory, read back by the
/// post-processor).
RunCommands writtenCommands(const MachineModel& m, const postproc::testprog::RunMotion& r, const postproc::testprog::TestProgram& prog,
                            const VerifyOptions& options) {
    return samplesOf(r, postproc::testprog::readTestProgram(m, r, prog.text, options.dialect, prog.file));
}

}  // namespace

std::shared_ptr<const controllers::AppliedCompensation> idealCompensation(const MachineModel& machine,
                                                                          const DeviationSet& identified) {
    return std::make_shared<IdealCompensation>(machine, identified);
}

PlanWorkspace planWorkspace(const MachineModel& m, const MeasurementPlan& plan, const VerifyOptions& options) {
    const std::vector<postproc::testprog::RunMotion> motions = postproc::testprog::planMotions(m, plan);
    postproc::testprog::TestProgramOptions po;
    po.dialect = options.dialect;
    const postproc::testprog::TestProgramSet programs = postproc::testprog::makeTestPrograms(m, plan, po);
    std::vector<RunCommands> programmed;
    for (size_t i = 0; i < motions.size(); ++i) programmed.push_back(writtenCommands(m, motions[i], programs.programs[i], options));
    return gridOver(m, motions, programmed, options.volumetricPerAxis);
}

double VerifyRun::spanBefore() const {
    double s = 0;
    for (const auto& p : passes) s = std::max(s, p.spanBefore);
    return s;
}
double VerifyRun::spanAfter() const {
    double s = 0;
    for (const auto& p : passes) s = std::max(s, p.spanAfter);
    return s;
}

VerifyResult verify(const MachineModel& m, const MeasurementPlan& plan, const DeviationSet& simulated,
                    const std::string& simulatedName, const VerifyCompensation& comp, const VerifyOptions& options) {
    if (comp.kind == VerifyCompensation::Kind::None) throw ModelError("verify: no compensation given");
    if ((comp.kind == VerifyCompensation::Kind::Deviations || comp.kind == VerifyCompensation::Kind::ControllerFiles) && !comp.model)
        throw ModelError("verify: the compensation has no controller model");
    const Kinematics k(m, simulated), nominal(m);
    VerifyResult out;
    out.machine = m.name;
    out.simulated = simulatedName;
    out.compensation = comp.description;
    if (!plan.sphereRuns.empty()) {
        // Sphere probing (verify_sphere.hpp): the spread of the fitted sphere centres over the poses.
        if (!comp.model)
            throw ModelError("verify: a sphere plan takes a deviation set or controller files (a corrected program carries "
                             "no probing moves)");
        out.runs = verifySphereRuns(m, plan, k, *comp.model, options.dialect);
        for (const VerifyRun& r : out.runs) {
            out.residualBefore = std::max(out.residualBefore, r.spanBefore());
            out.residual = std::max(out.residual, r.spanAfter());
        }
        out.volumetric.note = "sphere plans: no volumetric figure (the probing poses are not sampled as a workspace)";
    } else {
    const std::vector<postproc::testprog::RunMotion> motions = postproc::testprog::planMotions(m, plan);
    postproc::testprog::TestProgramOptions po;
    po.dialect = options.dialect;
    const postproc::testprog::TestProgramSet programs = postproc::testprog::makeTestPrograms(m, plan, po);
    std::vector<RunCommands> programmed;
    for (size_t i = 0; i < motions.size(); ++i) {
        const postproc::testprog::RunMotion& r = motions[i];
        const postproc::testprog::TestProgram& prog = programs.programs[i];
        // The commands as written: the program generated in memory, read back by the post-processor.
        const RunCommands before = writtenCommands(m, r, prog, options);
        RunCommands after;
        if (comp.kind == VerifyCompensation::Kind::CorrectedPrograms) {
            const auto it = std::find_if(comp.programs.begin(), comp.programs.end(), [&](const auto& p) { return p.first == r.name; });
            if (it == comp.programs.end()) throw InputError(comp.description, 0, fmt::format("no corrected program for run '{}'", r.name));
            const auto& [file, text] = it->second;
            after = samplesOf(r, postproc::testprog::readTestProgram(m, r, text, comp.programDialect, file));
        } else {
            // Each pose with the direction its axes' commands move in along the pass (lost_motion.hpp: a controller's
            // backlash or two-column table keys on it); the setup pose as reached from either side (0: the mean).
            after = before;
            const auto* directional = dynamic_cast<const controllers::common::DirectionalCompensation*>(comp.model.get());
            const auto drive = [&](const AxisVector& q, const AxisVector& motion) {
                return directional ? directional->driveCommandsMoving(q, r.toolLength, motion)
                                   : comp.model->driveCommandsForTool(q, r.toolLength);
            };
            after.setup = drive(before.setup, AxisVector::Zero(before.setup.size()));
            for (auto& pass : after.q) {
                const std::vector<AxisVector> motion = motionDirections(pass);
                for (size_t j = 0; j < pass.size(); ++j) pass[j] = drive(pass[j], motion[j]);
            }
        }
        VerifyRun run;
        run.name = r.name;
        run.kind = r.kind;
        run.type = runType(r);
        run.LB = barLength(r);
        run.program = prog.file;
        for (size_t p = 0; p < before.q.size(); ++p) {
            size_t pa = p;  // the corrected program's pass in the same direction
            for (size_t j = 0; j < after.labels.size(); ++j)
                if (after.labels[j] == before.labels[p]) pa = j;
            if (pa >= after.q.size() || after.t[pa] != before.t[p])
                throw InputError(comp.description, 0, fmt::format("run '{}': the corrected program's pass {} does not follow the "
                                                                  "plan's samples", r.name, before.labels[p]));
            VerifyPass v;
            v.label = before.labels[p];
            TravelCheck travelBefore, travelAfter;
            // The slides reach the drive commands with the simulated machine's lost motion at their reversals
            // (lost_motion.hpp; the setup pose at the mean of its two sides); none when the set has no reversal value.
            simulatePass(k, nominal, r, before.setup, before.setup, before.t[p], withLostMotion(simulated, before.q[p]), v.before,
                         v.displacementBefore, travelBefore);
            simulatePass(k, nominal, r, after.setup, before.setup, after.t[pa], withLostMotion(simulated, after.q[pa]), v.after,
                         v.displacementAfter, travelAfter);
            v.outsideTravel = travelAfter.describe(m);
            if (r.rtest) {
                v.spanBefore = displacementSpan(v.displacementBefore);
                v.spanAfter = displacementSpan(v.displacementAfter);
            } else {
                v.spanBefore = span(v.before.dL);
                v.spanAfter = span(v.after.dL);
                if (v.before.dL.size() >= 5) {
                    v.circular = true;
                    analyse(m, r, v.before, v.isoBefore, v.eccentricityBefore);
                    analyse(m, r, v.after, v.isoAfter, v.eccentricityAfter);
                }
            }
            run.passes.push_back(std::move(v));
        }
        out.residualBefore = std::max(out.residualBefore, run.spanBefore());
        out.residual = std::max(out.residual, run.spanAfter());
        out.runs.push_back(std::move(run));
        programmed.push_back(before);
    }
    if (comp.model) {
        volumetric(m, simulated, *comp.model, gridOver(m, motions, programmed, options.volumetricPerAxis), out.volumetric);
    } else {
        out.volumetric.note = "a corrected program compensates its own poses only: no volumetric figure";
    }
    }
    for (const controllers::Coverage& c : comp.notCompensated) {
        VerifyRemaining rem;
        rem.deviation = c.deviation;
        rem.reason = c.note;
        const int d = m.deviationIndex(c.deviation.substr(0, c.deviation.find(' ')));  // "EBB (constant part)" → EBB
        if (d >= 0) {
            const DeviationDef& def = m.deviations[static_cast<size_t>(d)];
            const double unit = def.isAngle() ? kArcsec : kUm;
            rem.valueKnown = true;
            rem.isoName = def.name;
            rem.unit = def.isAngle() ? "arcsec" : "um";
            if (def.kind == DeviationKind::Location) {
                rem.value = simulated.isoValue(d) / unit;  // the ISO value, not the link value (iso_names.hpp)
                if (!def.alias.empty()) rem.alias = def.alias, rem.aliasValue = simulated.aliasValue(d) / unit;
            } else {  // a component error: its largest coefficient, the same under either name
                double v = 0;
                for (int j = 0; j < def.size(); ++j) v = std::max(v, std::abs(simulated.values[def.offset + j]));
                rem.value = v / unit;
            }
        }
        out.remaining.push_back(rem);
    }
    out.worse = compensationWorse(out);
    return out;
}

VerifyWorse compensationWorse(const VerifyResult& r) {
    const auto allowance = [](double before) { return std::max(kWorseFloorMm, kWorseRelative * before); };
    VerifyWorse w;
    w.spanAllowance = allowance(r.residualBefore);
    w.span = r.residual > r.residualBefore + w.spanAllowance;
    for (const VerifyRun& run : r.runs)
        if (run.spanAfter() > run.spanBefore() + allowance(run.spanBefore()))
            w.runs.push_back(fmt::format("{} {:.3f} -> {:.3f} um", run.name, run.spanBefore() / kUm, run.spanAfter() / kUm));
    if (r.volumetric.available) {
        w.volumetricAllowance = allowance(r.volumetric.maxBefore);
        w.volumetric = r.volumetric.maxAfter > r.volumetric.maxBefore + w.volumetricAllowance;
    }
    return w;
}

std::string worseBanner(const VerifyResult& r) {
    const VerifyWorse& w = r.worse;
    if (!w.any()) return {};
    std::string s = "COMPENSATION MAKES THE MACHINE WORSE:";
    if (w.span)
        s += fmt::format(" largest dL span {:.3f} -> {:.3f} um (allowed growth {:.3f} um){}", r.residualBefore / kUm,
                         r.residual / kUm, w.spanAllowance / kUm, w.volumetric ? ";" : "");
    if (w.volumetric)
        s += fmt::format(" volumetric tool-tip error {:.3f} -> {:.3f} um (allowed growth {:.3f} um)", r.volumetric.maxBefore / kUm,
                         r.volumetric.maxAfter / kUm, w.volumetricAllowance / kUm);
    return s + "; do not load it";
}

}  // namespace cnccomp::app
