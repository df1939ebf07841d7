#include "postproc/testprog/test_program.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <optional>
#include <ostream>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/output_set.hpp"
#include "cnccomp/io/text_util.hpp"
#include "cnccomp/kinematics.hpp"

namespace cnccomp::postproc::testprog {
using namespace cnccomp::io;
using namespace cnccomp::measurement;

std::string programFileName(const std::string& run, int order, postproc::Dialect d) {
    std::string s = fmt::format("TP{:02d}_", order);
    for (char c : run) s.push_back(std::isalnum(static_cast<unsigned char>(c)) || c == '_' ? c : '_');
    return s + programExtension(d);
}

namespace {

std::string axisValue(const MachineModel& m, int a, double v) {
    return m.axisLink(a).kind == AxisKind::Rotary ? fmt::format("{:.4f} deg", v / kDeg) : fmt::format("{:.4f} mm", v);
}

/// First axis of q outside its travel, or -1.
int outsideTravel(const MachineModel& m, const AxisVector& q) {
    for (int a = 0; a < m.axisCount(); ++a) {
        const Link& l = m.axisLink(a);
        if (!(q[a] >= l.min - 1e-9 && q[a] <= l.max + 1e-9)) return a;
    }
    return -1;
}

[[noreturn]] void travelError(const MachineModel& m, const RunMotion& r, int a, const AxisVector& q, const std::string& where) {
    const Link& l = m.axisLink(a);
    throw ModelError(fmt::format("run '{}': axis {} would reach {} {}, outside its travel {} .. {} (machine '{}')", r.name,
                                 m.axisNames[a], axisValue(m, a, q[a]), where, axisValue(m, a, l.min), axisValue(m, a, l.max),
                                 m.name));
}

/// Parameters every `step` and half-way between, from `from` to `to` (both included).
std::vector<double> fineParameters(double from, double to, double step) {
    const double span = std::abs(to - from), dir = to >= from ? 1.0 : -1.0;
    const long n = std::max(1L, static_cast<long>(std::ceil(span / (std::abs(step) / 2) - 1e-9)));
    std::vector<double> t;
    for (long i = 0; i <= n; ++i) t.push_back(from + dir * std::min(span, i * std::abs(step) / 2));
    return t;
}

/// The linear axis that moves the tool point most directly away from the workpiece along the tool axis, and the
/// sign of its motion for a retract.
struct Retract {
    int axis = -1;
    double sign = 1;
};

Retract retractAxis(const Kinematics& k, const AxisVector& q, double toolLength) {
    const MachineModel& m = k.machine();
    const Vec3 tp = k.toolPoint(toolLength), tip = k.toolPointInWorkpiece(q, tp);
    const Vec3 back = (tip - k.toolPointInWorkpiece(q, k.toolPoint(toolLength + 1.0))).normalized();  // tip → spindle
    Retract r;
    double best = 0;
    for (int a = 0; a < m.axisCount(); ++a) {
        if (m.axisLink(a).kind != AxisKind::Linear) continue;
        AxisVector dq = q;
        dq[a] += 1.0;
        const double s = (k.toolPointInWorkpiece(dq, tp) - tip).dot(back);
        if (std::abs(s) > best) best = std::abs(s), r.axis = a, r.sign = s > 0 ? 1.0 : -1.0;
    }
    return r;
}

AxisVector retracted(const MachineModel& m, const AxisVector& q, const Retract& r, double clearance) {
    AxisVector p = q;
    if (r.axis < 0) return p;
    const Link& l = m.axisLink(r.axis);
    p[r.axis] = std::clamp(q[r.axis] + r.sign * clearance, std::min(l.min, q[r.axis]), std::max(l.max, q[r.axis]));
    return p;
}

/// Largest overshoot ≤ requested (in twentieths) whose path from `edge` outwards stays inside the travel.
double fitOvershoot(const MachineModel& m, const RunMotion& r, double edge, double outward, double requested, double step) {
    for (int k = 20; k > 0; --k) {
        const double o = requested * k / 20.0;
        bool ok = true;
        for (double t : fineParameters(edge, edge + outward * o, std::min(step, o)))
            if (outsideTravel(m, r.at(t)) >= 0) {
                ok = false;
                break;
            }
        if (ok) return o;
    }
    return 0.0;
}

std::string describePose(const MachineModel& m, const AxisVector& p) {
    std::string s;
    for (int a = 0; a < m.axisCount(); ++a) {
        const bool rotary = m.axisLink(a).kind == AxisKind::Rotary;
        s += fmt::format("{}{}={:.4f}", s.empty() ? "" : " ", m.axisNames[a], rotary ? p[a] / kDeg : p[a]);
    }
    return s;
}

struct Pass {
    std::vector<double> points;
    double overIn = 0, overOut = 0;  ///< overshoot before the first / after the last point, along the pass direction
    std::string label;
    double dir() const { return points.size() > 1 && points.back() < points.front() ? -1.0 : 1.0; }
};

}  // namespace

TestProgram makeTestProgram(const MachineModel& m, const RunMotion& r, int order, const TestProgramOptions& o) {
    if (r.points.empty()) throw ModelError(fmt::format("run '{}': no sweep points", r.name));
    for (double v : {o.feed, o.approachFeed})
        if (!(v > 0) || !std::isfinite(v)) throw ModelError(fmt::format("feeds must be positive, not {}", v));
    if (!(o.overshootDeg >= 0) || !(o.clearance >= 0) || !(o.dwellSeconds >= 0))
        throw ModelError("overshoot, clearance and dwell must be zero or positive");
    // A circle of the linear axes carries its own feed and overshoot in the plan (what its data import assumes).
    const double feed = r.circle ? r.circle->capture.feed : o.feed;
    const double overshoot = r.circle ? r.circle->capture.overshootDeg : o.overshootDeg;
    const Kinematics nominal(m);
    TestProgram tp;
    tp.run = r.name;
    tp.number = order;
    tp.kind = r.kind;
    tp.file = programFileName(r.name, order, o.dialect);
    tp.samples = r.sampleCount;

    // Everything the measurement needs must be inside the travel.
    if (const int a = outsideTravel(m, r.setup); a >= 0) travelError(m, r, a, r.setup, "at the setup pose");
    const auto& P = r.points;
    const double step = P.size() > 1 ? std::abs(P[1] - P[0]) : 1.0;
    for (double t : (r.continuous && P.size() > 1) ? fineParameters(P.front(), P.back(), step) : P) {
        const AxisVector q = r.at(t);
        if (const int a = outsideTravel(m, q); a >= 0) travelError(m, r, a, q, fmt::format("at {} {:g} of the sweep", r.parameter, t));
    }
    // Overshoot: as requested where the travel allows.
    const double dirF = P.back() >= P.front() ? 1.0 : -1.0;
    double oS = 0, oE = 0;
    PathShape shape;
    if (r.continuous && P.size() > 1) {
        oS = fitOvershoot(m, r, P.front(), -dirF, overshoot, step);
        oE = fitOvershoot(m, r, P.back(), dirF, overshoot, step);
        shape = analysePath(m, r, P.front() - dirF * oS, P.back() + dirF * oE, step);
        if (shape.circle) {
            // One circular block per step / overshoot: keep each well below half a turn.
            const double cap = 170.0 * kDeg / std::abs(shape.rate);
            oS = std::min(oS, cap), oE = std::min(oE, cap);
        }
    }
    tp.overshootStart = oS;
    tp.overshootEnd = oE;
    auto syntax = ProgramSyntax::make(o.dialect, m, o.decimals);
    const bool arcs = shape.circle && (syntax->arcsWithRotaryAxes() || !shape.rotaryMoves) &&
                      std::abs(shape.rate * step) < 170.0 * kDeg;
    tp.arcs = arcs;
    // Passes: CW first for circles, forward first otherwise.
    const bool forwardCcw = shape.circle && shape.rate * dirF > 0;
    Pass forward{P, oS, oE, ""}, backward{std::vector<double>(P.rbegin(), P.rend()), oE, oS, ""};
    // A circle of the linear axes: the plan's first direction first (CCW first when it says so).
    const bool ccwFirst = r.circle && r.circle->directions().front() > 0;
    std::array<Pass, 2> passes = forwardCcw != ccwFirst ? std::array<Pass, 2>{backward, forward}
                                                        : std::array<Pass, 2>{forward, backward};
    if (shape.circle) {
        passes[0].label = ccwFirst ? "CCW" : "CW";
        passes[1].label = ccwFirst ? "CW" : "CCW";
    } else {
        passes[0].label = "forward";
        passes[1].label = "reverse";
    }
    tp.firstPass = passes[0].label;

    const auto C = [&](const AxisVector& q) { return m.toController(q); };
    const unsigned all = m.axisCount() >= 32 ? ~0u : (1u << m.axisCount()) - 1u;
    const auto segment = [&](double t0, double t1, bool split) {
        if (arcs) {
            ArcBlock a;
            a.plane = shape.plane;
            a.axis0 = shape.axis0;
            a.axis1 = shape.axis1;
            a.c0 = shape.c0;
            a.c1 = shape.c1;
            a.ccw = shape.rate * (t1 - t0) > 0;
            syntax->arc(C(r.at(t1)), a, feed);
            return;
        }
        const long n = split ? std::max(1L, static_cast<long>(std::ceil(std::abs(t1 - t0) / step - 1e-9))) : 1;
        for (long i = 1; i <= n; ++i) syntax->line(C(r.at(t0 + (t1 - t0) * static_cast<double>(i) / n)), feed);
    };

    // Header.
    syntax->begin(tp.file.substr(0, tp.file.find('.')), 1000 + order);
    syntax->comment(fmt::format("cnccomp test program: {} run '{}' ({} of the plan)", runKindName(r.kind), r.name, order));
    syntax->comment(fmt::format("machine: {}{}{}", m.name, o.machineFile.empty() ? "" : " (" + o.machineFile + ")",
                                o.planFile.empty() ? "" : ", plan: " + o.planFile));
    if (syntax->passToolLength(r.toolLength)) {
        syntax->comment(fmt::format("dialect {}: positions in the controller's machine coordinates (mm, deg), no work offset; "
                                    "G43.1 Z{:g} gives the tool length: LinuxCNC adds it to every Z word, so Z is written as "
                                    "the machine coordinate minus {:g}",
                                    postproc::dialectName(o.dialect, postproc::DialectUse::Write), r.toolLength, r.toolLength));
        syntax->comment("cnccomp's LinuxCNC kinematics component (emit --controller linuxcnc) keeps the tool tip at that length exact "
                        "where the tool axis cannot follow");
    } else {
        syntax->comment(fmt::format("dialect {}: positions in the controller's machine coordinates (mm, deg), no tool length or "
                                    "work offset active",
                                    postproc::dialectName(o.dialect, postproc::DialectUse::Write)));
    }
    // The mode the controller must run the program in, which verify also runs it in.
    syntax->comment(kKinematicsModeLine);
    for (const std::string& n : r.notes) syntax->comment(n);
    syntax->comment("setup pose: " + describePose(m, C(r.setup)));
    syntax->comment(fmt::format("sweep parameter: {}, {} samples{}", r.parameter, r.sampleCount,
                                r.continuous ? "" : fmt::format(", dwell {:g} s at each pose", o.dwellSeconds)));
    syntax->comment(fmt::format("feed: {:g} mm/min on the sweep, {:g} mm/min onto the setup and start poses", feed, o.approachFeed));
    if (shape.circle)
        syntax->comment(fmt::format("path: circle of radius {:.4f} mm in the {} plane about ({:.4f}, {:.4f}){}, {}", shape.radius,
                                    shape.plane == 17 ? "XY" : shape.plane == 18 ? "ZX" : "YZ", shape.c0, shape.c1,
                                    shape.rotaryMoves ? " with the rotary axis turning" : "",
                                    arcs ? "circular blocks" : "straight blocks between the samples (chords)"));
    syntax->comment(fmt::format("direction of travel: first {} ({} {:g} to {:g}), then {} back", passes[0].label, r.parameter,
                                passes[0].points.front(), passes[0].points.back(), passes[1].label));
    if (r.continuous)
        syntax->comment(fmt::format("overshoot: {:g} deg before {:g} and {:g} deg after {:g}{}", oS, P.front(), oE, P.back(),
                                    oS < overshoot || oE < overshoot
                                        ? fmt::format(" (requested {:g}: shortened by the travel or the block length)", overshoot)
                                        : ""));
    syntax->comment("instrument: set it at the first stop, start the data capture at the second stop, stop it at the last "
                    "stop");
    // `cnccomp correct` reads the length back from this line when no --tool-length is given (postproc::toolLengthFromHeader).
    syntax->comment(fmt::format("to correct this program for the measured machine: cnccomp correct --tool-length {:g}", r.toolLength));
    for (const std::string& g : syntax->unconfirmed()) syntax->comment(g);
    syntax->init();

    // Approach and setup.
    const Retract rs = retractAxis(nominal, r.setup, r.toolLength);
    const AxisVector safeSetup = retracted(m, r.setup, rs, o.clearance);
    if (const int a = outsideTravel(m, safeSetup); a >= 0) travelError(m, r, a, safeSetup, "on the approach");
    syntax->comment("approach: retract axis first, then the other axes, then onto the setup pose");
    syntax->rapid(C(safeSetup), rs.axis >= 0 ? 1u << rs.axis : all);
    syntax->rapid(C(safeSetup), all);
    syntax->line(C(r.setup), o.approachFeed);
    syntax->comment("CNCCOMP SETUP");
    syntax->stop(r.setupAction);
    const Pass& p1 = passes[0];
    double t = p1.points.front() - p1.dir() * p1.overIn;
    if (r.continuous) {
        const AxisVector qStart = r.at(t);
        const AxisVector safeStart = retracted(m, qStart, retractAxis(nominal, qStart, r.toolLength), o.clearance);
        if (const int a = outsideTravel(m, safeStart); a >= 0) travelError(m, r, a, safeStart, "on the way to the start pose");
        syntax->rapid(C(safeSetup), all);
        syntax->rapid(C(safeStart), all);
        syntax->line(C(qStart), o.approachFeed);
    }
    syntax->stop(r.captureAction);

    // The measured passes.
    int k = 0;
    for (const Pass& p : passes) {
        ++k;
        const double d = p.dir();
        if (p.overIn > 0) segment(p.points.front() - d * p.overIn, p.points.front(), true);
        syntax->comment(fmt::format("CNCCOMP PASS {} {} BEGIN", k, p.label));
        if (!r.continuous) syntax->dwell(o.dwellSeconds);
        for (size_t i = 1; i < p.points.size(); ++i) {
            segment(p.points[i - 1], p.points[i], false);
            if (!r.continuous) syntax->dwell(o.dwellSeconds);
        }
        syntax->comment(fmt::format("CNCCOMP PASS {} END", k));
        if (p.overOut > 0) segment(p.points.back(), p.points.back() + d * p.overOut, true);
        t = p.points.back() + d * p.overOut;
    }
    syntax->stop("STOP THE DATA CAPTURE, THEN CYCLE START TO RETRACT");
    const AxisVector qEnd = r.at(t);
    const Retract re = retractAxis(nominal, qEnd, r.toolLength);
    syntax->rapid(C(retracted(m, qEnd, re, o.clearance)), re.axis >= 0 ? 1u << re.axis : all);
    syntax->end();
    tp.text = syntax->text();
    return tp;
}

TestProgramSet makeTestPrograms(const MachineModel& m, const MeasurementPlan& plan, const TestProgramOptions& o) {
    const std::vector<RunMotion> motions = planMotions(m, plan);
    if (motions.empty() && !plan.sphereRuns.empty())
        throw ModelError("the plan's sphere runs are probed by one program (probe_program.hpp: makeProbeProgram)");
    if (motions.empty()) throw ModelError("the plan has no runs");
    TestProgramSet set;
    set.index = "order,run,kind,file,samples,first_pass,arcs,overshoot_start_deg,overshoot_end_deg\n";
    int order = 0;
    for (const RunMotion& r : motions) {
        set.programs.push_back(makeTestProgram(m, r, ++order, o));
        const TestProgram& p = set.programs.back();
        for (const TestProgram& q : set.programs)
            if (&q != &p && q.file == p.file)
                throw ModelError(fmt::format("runs '{}' and '{}' give the same program file name", q.run, p.run));
        set.index += fmt::format("{},{},{},{},{},{},{},{:g},{:g}\n", p.number, p.run, runKindName(p.kind), p.file, p.samples,
                                 p.firstPass, p.arcs ? 1 : 0, p.overshootStart, p.overshootEnd);
    }
    return set;
}

void writeTestPrograms(const TestProgramSet& set, const std::string& dir, const std::vector<std::string>& inputs) {
    // All or none (io/output_set.hpp): every program is staged beside its target, then all are renamed together; a
    // full disk or a read-only folder leaves the targets as they were and removes a folder this call created.
    OutputSet out(inputs);
    out.makeFolder(dir);
    for (const TestProgram& p : set.programs) out.add(OutputSet::fileIn(dir, p.file), p.text);
    out.add(OutputSet::fileIn(dir, set.indexFile), set.index);
    out.commit();
}

}  // namespace cnccomp::postproc::testprog
