#include "app/verify_sphere.hpp"

#include <cmath>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/identification/sphere_probe.hpp"
#include "cnccomp/measurement/sphere_fit.hpp"
#include "postproc/testprog/probe_program.hpp"
#include "postproc/testprog/read_back.hpp"

namespace cnccomp::app {
using namespace cnccomp::identification;
using namespace cnccomp::measurement;
namespace {

/// Parameter t in [0, 1] where the stylus, driven to drive(t), is `radius` from `sphere`.
template <typename Drive>
std::optional<double> trigger(const Kinematics& k, const Vec3& tip, const Drive& drive, const Vec3& sphere, double radius) {
    return bracketedRoot([&](double t) { return (k.toolPointInWorkpiece(drive(t), tip) - sphere).norm() - radius; }, 0.0, 1.0);
}

double componentSpan(const std::vector<Vec3>& d) {
    double s = 0;
    for (int c = 0; c < 3; ++c) {
        double lo = 1e300, hi = -1e300;
        for (const Vec3& x : d) lo = std::min(lo, x[c]), hi = std::max(hi, x[c]);
        if (!d.empty()) s = std::max(s, hi - lo);
    }
    return s;
}

}  // namespace

std::vector<VerifyRun> verifySphereRuns(const MachineModel& m, const MeasurementPlan& plan, const Kinematics& k,
                                        const controllers::AppliedCompensation& model, postproc::Dialect dialect) {
    postproc::testprog::ProbeProgramOptions po;
    po.dialect = dialect;
    const postproc::testprog::ProbeProgram prog = postproc::testprog::makeProbeProgram(m, plan, po);
    // The probing targets as written, read back by cnccomp's reader.
    const std::vector<AxisVector> targets =
        postproc::testprog::readProbeTargets(m, prog.files[0].text, dialect, prog.files[0].file);
    if (targets.size() != prog.targets.size())
        throw ModelError(fmt::format("verify: the probing program reads back {} probing moves, the plan has {}", targets.size(),
                                     prog.targets.size()));
    const SpherePlanCommands cmds = sphereCommands(m, plan.sphereRuns);
    const Kinematics nominal(m);
    std::vector<VerifyRun> out;
    size_t next = 0;
    for (const SphereRunCommands& rc : cmds.runs) {
        const SphereRun& run = rc.run;
        const Vec3 tip = stylusPoint(m, run), sphere = run.centre + run.sphereOffset;
        const double radius = 0.5 * (run.diameter + run.stylusDiameter) - (run.triggerOffset + run.triggerError);
        std::vector<Vec3> before, after;
        for (const SpherePoseCommand& pc : rc.poses) {
            std::vector<Vec3> ptsBefore, ptsAfter;
            for (size_t t = 0; t < pc.touches.size(); ++t, ++next) {
                const AxisVector& a = prog.targets[next].approach;
                const AxisVector& b = targets[next];
                const auto programmed = [&](double s) { return AxisVector(a + s * (b - a)); };
                const auto compensated = [&](double s) { return model.driveCommandsForTool(programmed(s), run.toolLength); };
                const auto tb = trigger(k, tip, programmed, sphere, radius);
                const auto ta = trigger(k, tip, compensated, sphere, radius);
                if (!tb || !ta)
                    throw ModelError(fmt::format("verify: sphere run '{}' pose {} touch {}: the probing move misses the sphere "
                                                 "{} compensation",
                                                 run.name, pc.planPose, t, tb ? "with" : "without"));
                // The controller records the programmed coordinates at the trigger (#5061…).
                ptsBefore.push_back(nominal.toolPointInWorkpiece(programmed(*tb), tip));
                ptsAfter.push_back(nominal.toolPointInWorkpiece(programmed(*ta), tip));
            }
            before.push_back(fitSphereKnownRadius(ptsBefore, run.fitRadius(), run.centre).centre);
            after.push_back(fitSphereKnownRadius(ptsAfter, run.fitRadius(), run.centre).centre);
        }
        VerifyRun vr;
        vr.name = run.name;
        vr.kind = postproc::testprog::RunKind::Rtest;
        vr.type = "sphere probing (centre spread)";
        vr.program = prog.files[0].file;
        VerifyPass p;
        p.label = "poses";
        const auto fill = [](const std::vector<Vec3>& c, std::vector<Vec3>& d, BallbarTrace& tr) {
            Vec3 mean = Vec3::Zero();
            for (const Vec3& x : c) mean += x / static_cast<double>(c.size());
            for (size_t i = 0; i < c.size(); ++i) {
                d.push_back(c[i] - mean);
                tr.angleDeg.push_back(static_cast<double>(i));
                tr.dL.push_back(d.back().norm());
            }
        };
        fill(before, p.displacementBefore, p.before);
        fill(after, p.displacementAfter, p.after);
        p.spanBefore = componentSpan(p.displacementBefore);
        p.spanAfter = componentSpan(p.displacementAfter);
        vr.passes.push_back(std::move(p));
        out.push_back(std::move(vr));
    }
    return out;
}

}  // namespace cnccomp::app
