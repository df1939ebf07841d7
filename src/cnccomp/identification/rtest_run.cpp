#include "cnccomp/identification/rtest_run.hpp"

#include <cmath>
#include <set>

#include <Eigen/QR>
#include <fmt/format.h>

#include "cnccomp/error.hpp"

namespace cnccomp::identification {
using namespace cnccomp::measurement;

AxisVector followPoint(const Kinematics& k, AxisVector q, const Vec3& toolPoint, const Vec3& target) {
    const MachineModel& m = k.machine();
    std::vector<int> lin;
    for (int i = 0; i < m.axisCount(); ++i)
        if (m.axisLink(i).kind == AxisKind::Linear) lin.push_back(i);
    if (lin.size() < 3)
        throw ModelError(fmt::format("machine '{}' has {} linear axes; three are needed to follow a point", m.name,
                                     lin.size()));
    Eigen::MatrixXd J(3, static_cast<Eigen::Index>(lin.size()));
    for (int it = 0; it < 20; ++it) {
        const Vec3 f = k.toolPointInWorkpiece(q, toolPoint) - target;
        if (f.norm() < 1e-12 * (1.0 + target.norm())) return q;
        // Central differences: the tool point is affine in the linear axes unless they carry component errors.
        for (size_t j = 0; j < lin.size(); ++j) {
            AxisVector a = q, b = q;
            a[lin[j]] += 1.0;
            b[lin[j]] -= 1.0;
            J.col(static_cast<Eigen::Index>(j)) =
                0.5 * (k.toolPointInWorkpiece(a, toolPoint) - k.toolPointInWorkpiece(b, toolPoint));
        }
        Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(J);
        if (qr.rank() < 3)
            throw ModelError(fmt::format("machine '{}': the linear axes cannot move the tool point in three directions",
                                         m.name));
        const Eigen::VectorXd step = qr.solve(f);
        for (size_t j = 0; j < lin.size(); ++j) q[lin[j]] -= step[static_cast<Eigen::Index>(j)];
    }
    const Vec3 f = k.toolPointInWorkpiece(q, toolPoint) - target;
    if (f.norm() > 1e-9) throw ModelError(fmt::format("machine '{}': cannot put the tool point on the target", m.name));
    return q;
}

std::vector<AxisVector> rtestCommands(const MachineModel& m, const RtestRun& run) {
    run.validate();
    const Kinematics nominal(m);
    std::vector<int> index;
    for (const RotarySweep& s : run.sweeps) {
        const int i = m.axisIndex(s.axis);
        if (i < 0) throw ModelError(fmt::format("R-test run '{}': machine '{}' has no axis '{}'", run.name, m.name, s.axis));
        if (m.axisLink(i).kind != AxisKind::Rotary)
            throw ModelError(fmt::format("R-test run '{}': axis '{}' is not rotary", run.name, s.axis));
        index.push_back(i);
    }
    const Vec3 nest = nominal.toolPoint(run.nestLength);
    const int n = run.sampleCount();
    std::vector<AxisVector> out;
    out.reserve(static_cast<size_t>(n));
    AxisVector q = AxisVector::Zero(m.axisCount());
    for (int i = 0; i < n; ++i) {
        for (size_t s = 0; s < index.size(); ++s) q[index[s]] = run.angleDeg(static_cast<int>(s), i) * kDeg;
        q = followPoint(nominal, q, nest, run.ball);
        try {
            nominal.checkTravel(q);
        } catch (const ModelError& e) {
            throw ModelError(fmt::format("R-test run '{}' pose {}: {}", run.name, i + 1, e.what()));
        }
        out.push_back(q);
    }
    return out;
}

Vec3 rtestDisplacement(const Kinematics& k, const AxisVector& q, const Vec3& ball, const Vec3& nest) {
    return k.workpieceToTool(q).inverse(Eigen::Isometry) * ball - nest;
}

RtestTrace simulateRtest(const Kinematics& k, const RtestRun& run, const std::vector<AxisVector>& commands) {
    RtestTrace t;
    t.commands = commands;
    t.d.reserve(commands.size());
    const Vec3 nest = k.toolPoint(run.nestLength);
    const Vec3 ball = run.ball + run.ballOffset;
    for (const AxisVector& q : commands) t.d.push_back(rtestDisplacement(k, q, ball, nest));
    return t;
}

RtestTrace simulateRtest(const Kinematics& k, const RtestRun& run) {
    return simulateRtest(k, run, rtestCommands(k.machine(), run));
}

}  // namespace cnccomp::identification
