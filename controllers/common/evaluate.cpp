#include "controllers/common/evaluate.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/inverse_kinematics.hpp"

namespace cnccomp::controllers::common {
namespace {

double angleBetween(const Vec3& a, const Vec3& b) { return std::atan2(a.cross(b).norm(), a.dot(b)); }

}  // namespace

CompensationFigures evaluateCompensation(const MachineModel& m, const DeviationSet& truth,
                                         const AppliedCompensation& comp, const std::vector<AxisVector>& programmed,
                                         double toolLength) {
    if (!std::isfinite(toolLength)) throw ModelError("tool length must be a finite number");
    const Kinematics nominal(m);
    const Kinematics actual(m, truth);
    const Vec3 tip = nominal.toolPoint(toolLength);
    CompensationFigures f;
    double sumBefore = 0, sumAfter = 0;
    for (const AxisVector& q : programmed) {
        if (q.size() != m.axisCount())
            throw ModelError(fmt::format("machine '{}' has {} axes, a sample has {}", m.name, m.axisCount(), q.size()));
        const ToolPose target = toolPose(nominal, q, tip);
        const ToolPose before = toolPose(actual, q, tip);
        const AxisVector drive = comp.driveCommandsForTool(q, toolLength);
        if (drive.size() != q.size() || !drive.allFinite())
            throw ModelError("compensation model returned drive commands of the wrong size or not finite");
        const ToolPose after = toolPose(actual, drive, tip);
        const double eb = (before.tip - target.tip).norm();
        const double ea = (after.tip - target.tip).norm();
        f.maxBefore = std::max(f.maxBefore, eb);
        f.maxAfter = std::max(f.maxAfter, ea);
        sumBefore += eb * eb;
        sumAfter += ea * ea;
        f.maxAxisBefore = std::max(f.maxAxisBefore, angleBetween(before.axis, target.axis));
        f.maxAxisAfter = std::max(f.maxAxisAfter, angleBetween(after.axis, target.axis));
        ++f.points;
    }
    if (f.points > 0) {
        f.rmsBefore = std::sqrt(sumBefore / f.points);
        f.rmsAfter = std::sqrt(sumAfter / f.points);
    }
    return f;
}

std::vector<AxisVector> workspaceSamples(const MachineModel& m, int perAxis, double maxLinear) {
    if (perAxis < 1) throw ModelError("workspace samples: at least one sample per axis");
    const int n = m.axisCount();
    std::vector<double> lo(n), hi(n);
    for (int i = 0; i < n; ++i) {
        const Link& l = m.axisLink(i);
        const double lim = l.kind == AxisKind::Rotary ? kPi : maxLinear;
        lo[i] = std::max(l.min, -lim);
        hi[i] = std::min(l.max, lim);
        if (lo[i] > hi[i]) lo[i] = hi[i] = std::clamp(0.0, l.min, l.max);
    }
    const auto value = [&](int axis, int k) {
        if (perAxis == 1) return 0.5 * (lo[axis] + hi[axis]);
        return lo[axis] + (hi[axis] - lo[axis]) * k / (perAxis - 1);
    };
    long total = 1;
    for (int i = 0; i < n; ++i) {
        total *= perAxis;
        if (total > 50'000'000) throw ModelError("workspace samples: more than 50 million points");
    }
    std::vector<AxisVector> out;
    out.reserve(static_cast<size_t>(total));
    std::vector<int> idx(n, 0);
    for (long s = 0; s < total; ++s) {
        AxisVector q(n);
        for (int i = 0; i < n; ++i) q[i] = value(i, idx[i]);
        out.push_back(q);
        for (int i = n - 1; i >= 0; --i) {
            if (++idx[i] < perAxis) break;
            idx[i] = 0;
        }
    }
    return out;
}

CompensationFigures emitApplyEvaluate(const Backend& b, const MachineModel& m, const DeviationSet& truth,
                                      const std::vector<AxisVector>& programmed, double toolLength) {
    const EmitRequest request{m, truth, "evaluation", "2000-01-01"};
    const EmitResult emitted = b.emit(request);
    const auto comp = b.apply(m, emitted.files);
    if (!comp) throw ModelError(fmt::format("backend '{}' returned no compensation model", b.name()));
    return evaluateCompensation(m, truth, *comp, programmed, toolLength);
}

}  // namespace cnccomp::controllers::common
