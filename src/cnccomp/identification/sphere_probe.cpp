#include "cnccomp/identification/sphere_probe.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <set>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/identification/rtest_run.hpp"
#include "cnccomp/measurement/sphere_fit.hpp"

namespace cnccomp::identification {
using namespace cnccomp::measurement;
namespace {

std::string poseText(const SpherePose& p) {
    std::string s;
    for (const auto& [axis, deg] : p) s += fmt::format("{}{}={:g}", s.empty() ? "" : " ", axis, deg);
    return s.empty() ? "rotary axes at 0" : s;
}

/// Parameter along the probing move where the stylus centre is `radius` from `sphere`, bracketed in [lo, hi].
std::optional<double> triggerParameter(const Kinematics& k, const Vec3& stylus, const AxisVector& from, const AxisVector& to,
                                       const Vec3& sphere, double radius, double lo, double hi) {
    return bracketedRoot(
        [&](double t) {
            const AxisVector q = from + t * (to - from);
            return (k.toolPointInWorkpiece(q, stylus) - sphere).norm() - radius;
        },
        lo, hi);
}

AxisVector setPoseAngles(const MachineModel& m, const SphereRun& run, const SpherePose& pose) {
    AxisVector q = AxisVector::Zero(m.axisCount());
    for (const auto& [axis, deg] : pose) {
        const int i = m.axisIndex(axis);
        if (i < 0) throw ModelError(fmt::format("sphere run '{}': machine '{}' has no axis '{}'", run.name, m.name, axis));
        if (m.axisLink(i).kind != AxisKind::Rotary)
            throw ModelError(fmt::format("sphere run '{}': axis '{}' is not rotary", run.name, axis));
        q[i] = deg * kDeg;
    }
    return q;
}

}  // namespace

int SpherePlanCommands::poseCount() const {
    int n = 0;
    for (const SphereRunCommands& r : runs) n += static_cast<int>(r.poses.size());
    return n;
}

Vec3 stylusPoint(const MachineModel& machine, const SphereRun& run) { return machine.toolDirection * run.toolLength; }

std::optional<AxisVector> probeTrigger(const Kinematics& k, const Vec3& stylus, const AxisVector& from, const AxisVector& to,
                                       const Vec3& sphere, double radius, double lo, double hi) {
    const auto t = triggerParameter(k, stylus, from, to, sphere, radius, lo, hi);
    if (!t) return std::nullopt;
    return AxisVector(from + *t * (to - from));
}

SpherePlanCommands sphereCommands(const MachineModel& m, const std::vector<SphereRun>& runs) {
    const Kinematics nom(m);
    SpherePlanCommands out;
    if (runs.empty()) return out;
    // Park axis: the linear axis that moves the tool most along the tool direction at the zero pose; "up" = away.
    const AxisVector q0 = AxisVector::Zero(m.axisCount());
    const Vec3 tip0 = stylusPoint(m, runs.front());
    const Vec3 up0 = -(nom.workpieceToTool(q0).linear() * m.toolDirection);
    double best = 0, upSign = 1;
    for (int i = 0; i < m.axisCount(); ++i) {
        if (m.axisLink(i).kind != AxisKind::Linear) continue;
        AxisVector q1 = q0;
        q1[i] += 1.0;
        const double s = (nom.toolPointInWorkpiece(q1, tip0) - nom.toolPointInWorkpiece(q0, tip0)).dot(up0);
        if (std::abs(s) > std::abs(best)) best = s, out.parkAxis = i, upSign = s > 0 ? 1.0 : -1.0;
    }
    if (out.parkAxis < 0 || std::abs(best) < 0.5)
        throw ModelError(fmt::format("machine '{}': no linear axis moves the tool along its axis (needed to retract the "
                                     "probe between poses)",
                                     m.name));
    int planPose = 0;
    double maxClearance = 0;
    for (const SphereRun& run : runs) {
        run.validate();
        maxClearance = std::max(maxClearance, run.clearance);
        SphereRunCommands rc;
        rc.run = run;
        const Vec3 tip = stylusPoint(m, run);
        const double R = 0.5 * (run.diameter + run.stylusDiameter);
        const Vec3& c = run.centre;
        for (const SpherePose& pose : run.poses()) {
            SpherePoseCommand pc;
            pc.planPose = planPose++;
            pc.angles = pose;
            const auto where = [&](int touch) {
                return touch < 0 ? fmt::format("sphere run '{}' pose {} ({})", run.name, pc.planPose, poseText(pose))
                                 : fmt::format("sphere run '{}' pose {} ({}) touch {}", run.name, pc.planPose,
                                               poseText(pose), touch);
            };
            AxisVector q = setPoseAngles(m, run, pose);
            const Pose wMt = nom.workpieceToTool(q);
            const Vec3 u = -(wMt.linear() * m.toolDirection).normalized();
            Vec3 ex = wMt.linear() * Vec3::UnitX();
            ex -= u * u.dot(ex);
            if (ex.norm() < 1e-6) {
                ex = wMt.linear() * Vec3::UnitY();
                ex -= u * u.dot(ex);
            }
            ex.normalize();
            const Vec3 ey = u.cross(ex);
            const auto axes = [&](const Vec3& p, int touch, const char* what) {
                AxisVector a;
                try {
                    a = followPoint(nom, q, tip, p);
                    nom.checkTravel(a);
                } catch (const ModelError& e) {
                    throw ModelError(fmt::format("{}: the {} point: {}", where(touch), what, e.what()));
                }
                return a;
            };
            const Vec3 S = c + (R + run.clearance) * u;
            pc.safe = axes(S, -1, "safe");
            const double phi = run.latitudeDeg * kDeg;
            for (int t = 0; t < run.touchesPerPose(); ++t) {
                Vec3 n = u;
                if (t > 0) {
                    const double th = 2.0 * M_PI * (t - 1) / run.ringTouches;
                    n = std::cos(phi) * (std::cos(th) * ex + std::sin(th) * ey) + std::sin(phi) * u;
                }
                const Vec3 P = c + (R + run.approach) * n, T = c + (R - run.approach) * n;
                const Vec3 A = P + ((R + run.clearance) - (P - c).dot(u)) * u;
                SphereTouchCommand tc;
                tc.normal = n;
                tc.above = axes(A, t, "clearance");
                tc.approach = axes(P, t, "approach");
                tc.target = axes(T, t, "probing target");
                pc.touches.push_back(tc);
            }
            rc.poses.push_back(std::move(pc));
        }
        out.runs.push_back(std::move(rc));
    }
    // Park value: beyond every safe point by the largest clearance, inside the travel.
    const Link& park = m.axisLink(out.parkAxis);
    double v = upSign > 0 ? -1e300 : 1e300;
    for (const SphereRunCommands& rc : out.runs)
        for (const SpherePoseCommand& pc : rc.poses)
            v = upSign > 0 ? std::max(v, pc.safe[out.parkAxis]) : std::min(v, pc.safe[out.parkAxis]);
    v += upSign * maxClearance;
    out.parkValue = std::clamp(v, park.min, park.max);
    // Every move between poses (up, across, down) stays half a clearance clear of every sphere.
    std::vector<const SpherePoseCommand*> seq;
    std::vector<const SphereRun*> seqRun;
    for (const SphereRunCommands& rc : out.runs)
        for (const SpherePoseCommand& pc : rc.poses) seq.push_back(&pc), seqRun.push_back(&rc.run);
    for (size_t i = 0; i + 1 < seq.size(); ++i) {
        AxisVector a = seq[i]->safe, b = seq[i + 1]->safe;
        AxisVector a1 = a, b1 = b;
        a1[out.parkAxis] = b1[out.parkAxis] = out.parkValue;
        const AxisVector path[] = {a, a1, b1, b};
        for (int s = 0; s < 3; ++s)
            for (int j = 0; j <= 64; ++j) {
                const AxisVector q = path[s] + (j / 64.0) * (path[s + 1] - path[s]);
                for (const SphereRunCommands& rc : out.runs) {
                    const double R = 0.5 * (rc.run.diameter + rc.run.stylusDiameter);
                    const double d = (nom.toolPointInWorkpiece(q, stylusPoint(m, *seqRun[i])) - rc.run.centre).norm();
                    if (d < R + 0.5 * rc.run.clearance - 1e-9)
                        throw ModelError(fmt::format(
                            "sphere run '{}': the move from pose {} ({}) to pose {} ({}) with {} at {:.3f} mm passes {:.3f} "
                            "mm from the centre of sphere '{}' (less than radius + half the clearance, {:.3f} mm): the "
                            "travel of {} does not let the probe retract far enough",
                            seqRun[i + 1]->name, seq[i]->planPose, poseText(seq[i]->angles), seq[i + 1]->planPose,
                            poseText(seq[i + 1]->angles), m.axisNames[static_cast<size_t>(out.parkAxis)], out.parkValue, d,
                            rc.run.name, R + 0.5 * rc.run.clearance, m.axisNames[static_cast<size_t>(out.parkAxis)]));
                }
            }
    }
    return out;
}

ProbeLog simulateSphereProbing(const Kinematics& k, const SpherePlanCommands& commands, double noise, unsigned long seed) {
    ProbeLog log;
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> normal(0.0, 1.0);
    const MachineModel& m = k.machine();
    for (const SphereRunCommands& rc : commands.runs) {
        const SphereRun& run = rc.run;
        const Vec3 tip = stylusPoint(m, run);
        const Vec3 sphere = run.centre + run.sphereOffset;
        const double radius = 0.5 * (run.diameter + run.stylusDiameter) - (run.triggerOffset + run.triggerError);
        for (const SpherePoseCommand& pc : rc.poses)
            for (size_t t = 0; t < pc.touches.size(); ++t) {
                const SphereTouchCommand& tc = pc.touches[t];
                ProbeTouch pt;
                pt.pose = pc.planPose;
                pt.touch = static_cast<int>(t);
                auto par = triggerParameter(k, tip, tc.approach, tc.target, sphere, radius, 0.0, 1.0);
                if (par && noise > 0) {
                    const double len = (k.toolPointInWorkpiece(tc.target, tip) - k.toolPointInWorkpiece(tc.approach, tip)).norm();
                    *par = std::clamp(*par + noise * normal(rng) / len, 0.0, 1.0);
                }
                pt.triggered = par ? 1 : 0;
                pt.q = par ? AxisVector(tc.approach + *par * (tc.target - tc.approach)) : tc.target;
                log.touches.push_back(pt);
            }
    }
    return log;
}

std::vector<std::vector<std::vector<AxisVector>>> checkedTouches(const MachineModel& m, const SpherePlanCommands& commands,
                                                                 const ProbeLog& log) {
    const Kinematics nom(m);
    struct Where {
        size_t run, pose;
    };
    std::vector<Where> poses;
    std::vector<std::vector<std::vector<AxisVector>>> out;
    std::vector<std::vector<std::vector<int>>> seen;
    for (size_t r = 0; r < commands.runs.size(); ++r) {
        out.emplace_back();
        seen.emplace_back();
        for (size_t p = 0; p < commands.runs[r].poses.size(); ++p) {
            poses.push_back({r, p});
            const size_t n = commands.runs[r].poses[p].touches.size();
            out[r].emplace_back(n);
            seen[r].emplace_back(n, 0);
        }
    }
    for (const ProbeTouch& t : log.touches) {
        const auto fail = [&](const std::string& what) {
            throw InputError(log.file, t.line, fmt::format("pose {} touch {}: {}", t.pose, t.touch, what));
        };
        if (t.pose < 0 || t.pose >= static_cast<int>(poses.size()))
            fail(fmt::format("the plan has poses 0 .. {}", static_cast<int>(poses.size()) - 1));
        const Where w = poses[static_cast<size_t>(t.pose)];
        const SphereRunCommands& rc = commands.runs[w.run];
        const SpherePoseCommand& pc = rc.poses[w.pose];
        if (t.touch < 0 || t.touch >= static_cast<int>(pc.touches.size()))
            fail(fmt::format("sphere run '{}' has touches 0 .. {} a pose", rc.run.name, pc.touches.size() - 1));
        int& s = seen[w.run][w.pose][static_cast<size_t>(t.touch)];
        if (s) fail(fmt::format("recorded twice (first on line {})", s));
        s = t.line > 0 ? t.line : 1;
        if (t.triggered == 0)
            fail(fmt::format("missed: the probe did not trigger on its probing move (sphere run '{}', {} mm either side of "
                             "the nominal surface); not fitted",
                             rc.run.name, rc.run.approach));
        if (t.q.size() != m.axisCount()) fail("wrong number of axis values");
        AxisVector q = t.q;
        for (int a = 0; a < m.axisCount(); ++a) {
            const bool rotary = m.axisLink(a).kind == AxisKind::Rotary;
            if (!std::isfinite(q[a])) {
                if (!rotary) fail(fmt::format("the file gives no position of axis {}", m.axisNames[static_cast<size_t>(a)]));
                q[a] = pc.safe[a];
            } else if (rotary && std::abs(q[a] - pc.safe[a]) > 1e-3 * kDeg) {
                fail(fmt::format("axis {} at {:.6f} deg, the pose has it at {:.6f} deg (is this the log of this plan?)",
                                 m.axisNames[static_cast<size_t>(a)], q[a] / kDeg, pc.safe[a] / kDeg));
            }
        }
        const SphereTouchCommand& tc = pc.touches[static_cast<size_t>(t.touch)];  // its commanded probing move
        // No flag in the file (Fanuc, HEIDENHAIN): a touch at the end of its probing move did not trigger.
        if (t.triggered < 0) {
            bool atEnd = true;
            for (int a = 0; a < m.axisCount(); ++a)
                if (m.axisLink(a).kind == AxisKind::Linear) atEnd = atEnd && std::abs(q[a] - tc.target[a]) < 1e-4;
            if (atEnd)
                fail(fmt::format("missed: the probe stopped at the end of its probing move (sphere run '{}'); not fitted",
                                 rc.run.name));
        }
        const double dev = (nom.toolPointInWorkpiece(q, stylusPoint(m, rc.run)) - rc.run.centre).norm() - rc.run.fitRadius();
        if (std::abs(dev) > rc.run.touchWindow())
            fail(fmt::format("the stylus ball centre is {:+.4f} mm from the nominal surface, outside the expected window "
                             "±{:g} mm of sphere run '{}'{}; not fitted",
                             dev, rc.run.touchWindow(), rc.run.name,
                             std::abs(dev + rc.run.approach) < 1e-3 ? " (at the end of its probing move: a missed touch)" : ""));
        // On its own probing move: the probe stops on the commanded line (approach → target in the linear axes; the
        // controllers log the trip position of that move). A contact on the sphere but off that line is another
        // move's, e.g. LinuxCNC's stale DONE repeating the last contact (postproc/testprog/probe_program.hpp).
        double uu = 0, ud = 0, dd = 0;
        for (int a = 0; a < m.axisCount(); ++a) {
            if (m.axisLink(a).kind != AxisKind::Linear) continue;
            const double u = q[a] - tc.approach[a], d = tc.target[a] - tc.approach[a];
            uu += u * u, ud += u * d, dd += d * d;
        }
        const double off = std::sqrt(std::max(0.0, dd > 0 ? uu - ud * ud / dd : uu));
        if (off > rc.run.touchWindow())
            fail(fmt::format("the probe stopped {:.4f} mm off the line of its probing move (more than the window ±{:g} mm "
                             "of sphere run '{}'): the position of another touch? not fitted",
                             off, rc.run.touchWindow(), rc.run.name));
        out[w.run][w.pose][static_cast<size_t>(t.touch)] = q;
    }
    for (size_t r = 0; r < commands.runs.size(); ++r)
        for (size_t p = 0; p < commands.runs[r].poses.size(); ++p)
            for (size_t t = 0; t < seen[r][p].size(); ++t)
                if (!seen[r][p][t])
                    throw InputError(log.file, 0,
                                     fmt::format("pose {} touch {} (sphere run '{}') is not in the file",
                                                 commands.runs[r].poses[p].planPose, t, commands.runs[r].run.name));
    return out;
}

SphereObservation::SphereObservation(const MachineModel& machine, const SphereRunCommands& commands,
                                     const std::vector<std::vector<AxisVector>>& touches)
    : machine_(&machine), nominal_(machine), cmd_(commands), stylus_(stylusPoint(machine, commands.run)) {
    if (touches.size() != cmd_.poses.size())
        throw ModelError(fmt::format("sphere run '{}': {} poses but touches of {}", cmd_.run.name, cmd_.poses.size(),
                                     touches.size()));
    measured_.resize(static_cast<Eigen::Index>(3 * touches.size()));
    std::vector<Vec3> pts;
    for (size_t p = 0; p < touches.size(); ++p) {
        pts.clear();
        for (const AxisVector& q : touches[p]) pts.push_back(nominal_.toolPointInWorkpiece(q, stylus_));
        const SphereFit f = fitSphereKnownRadius(pts, cmd_.run.fitRadius(), cmd_.run.centre);
        measured_.segment<3>(static_cast<Eigen::Index>(3 * p)) = f.centre - cmd_.run.centre;
        fitRms_.push_back(f.rms);
    }
}

std::vector<std::string> SphereObservation::nuisanceNames() const {
    std::vector<std::string> n{cmd_.run.name + ".xSphere", cmd_.run.name + ".ySphere", cmd_.run.name + ".zSphere"};
    if (cmd_.run.estimateTrigger) n.push_back(cmd_.run.name + ".trigger");
    return n;
}

void SphereObservation::nuisanceInitial(double* out) const {
    out[0] = out[1] = out[2] = 0.0;
    if (cmd_.run.estimateTrigger) out[3] = cmd_.run.triggerOffset;
}

void SphereObservation::predict(const Kinematics& k, const double* nuisance, double* out) const {
    const SphereRun& run = cmd_.run;
    const Vec3 sphere = run.centre + Vec3(nuisance[0], nuisance[1], nuisance[2]);
    const double trigger = run.estimateTrigger ? nuisance[3] : run.triggerOffset;
    const double radius = 0.5 * (run.diameter + run.stylusDiameter) - trigger;
    std::vector<Vec3> pts;
    for (size_t p = 0; p < cmd_.poses.size(); ++p) {
        pts.clear();
        for (size_t t = 0; t < cmd_.poses[p].touches.size(); ++t) {
            const SphereTouchCommand& tc = cmd_.poses[p].touches[t];
            // The probing move extended both ways (a trial of the solver may put the sphere beyond the move's ends), up
            // to the nominal centre (hi), where the move is still inside the sphere.
            const double hi = (0.5 * (run.diameter + run.stylusDiameter) + run.approach) / (2.0 * run.approach);
            const auto q = probeTrigger(k, stylus_, tc.approach, tc.target, sphere, radius, -20.0, hi);
            if (!q)
                throw ModelError(fmt::format("sphere run '{}': at the trial deviations pose {} touch {} does not meet the "
                                             "sphere",
                                             run.name, cmd_.poses[p].planPose, t));
            pts.push_back(nominal_.toolPointInWorkpiece(*q, stylus_));
        }
        const SphereFit f = fitSphereKnownRadius(pts, run.fitRadius(), run.centre);
        for (int c = 0; c < 3; ++c) out[3 * p + static_cast<size_t>(c)] = f.centre[c] - run.centre[c];
    }
}

std::vector<std::string> SphereObservation::turningAxes() const {
    std::map<std::string, std::set<double>> seen;
    for (const SpherePoseCommand& pc : cmd_.poses)
        for (const auto& [axis, deg] : pc.angles) seen[axis].insert(deg);
    std::vector<std::string> out;
    for (const auto& [axis, values] : seen)
        if (values.size() > 1) out.push_back(axis);
    return out;
}

Observations sphereObservations(const MachineModel& machine, const SpherePlanCommands& commands, const ProbeLog& log) {
    const auto touches = checkedTouches(machine, commands, log);
    Observations obs;
    for (size_t r = 0; r < commands.runs.size(); ++r)
        obs.push_back(std::make_unique<SphereObservation>(machine, commands.runs[r], touches[r]));
    return obs;
}

std::optional<double> bracketedRoot(const std::function<double(double)>& f, double lo, double hi) {
    double a = lo, b = hi, fa = f(a), fb = f(b);
    if (!(fa > 0 && fb <= 0)) return std::nullopt;
    int side = 0;
    for (int it = 0; it < 200; ++it) {
        const double t = (a * fb - b * fa) / (fb - fa);
        const double ft = f(t);
        if (std::abs(ft) < 1e-14 || std::abs(b - a) < 1e-15) return t;
        if (ft > 0) {
            a = t, fa = ft;
            if (side == 1) fb *= 0.5;
            side = 1;
        } else {
            b = t, fb = ft;
            if (side == -1) fa *= 0.5;
            side = -1;
        }
    }
    return 0.5 * (a + b);
}

}  // namespace cnccomp::identification
