#include "cnccomp/identification/rtest_observation.hpp"

#include <fmt/format.h>

#include "cnccomp/error.hpp"

namespace cnccomp::identification {
using namespace cnccomp::measurement;

RtestObservation::RtestObservation(const MachineModel& machine, RtestRun run, const RtestTrace& trace)
    : run_(std::move(run)), commands_(trace.commands) {
    run_.validate();
    if (trace.commands.size() != trace.d.size() || trace.d.empty())
        throw ModelError(fmt::format("R-test run '{}': {} poses but {} displacements", run_.name, trace.commands.size(),
                                     trace.d.size()));
    measured_.resize(static_cast<Eigen::Index>(3 * trace.d.size()));
    for (size_t i = 0; i < trace.d.size(); ++i) {
        if (!trace.d[i].allFinite() || !trace.commands[i].allFinite())
            throw ModelError(fmt::format("R-test run '{}': pose {} is not finite", run_.name, i + 1));
        if (trace.commands[i].size() != machine.axisCount())
            throw ModelError(fmt::format("R-test run '{}': pose {} has {} axis values, machine '{}' has {} axes",
                                         run_.name, i + 1, trace.commands[i].size(), machine.name, machine.axisCount()));
        measured_.segment<3>(static_cast<Eigen::Index>(3 * i)) = trace.d[i];
    }
}

std::vector<std::string> RtestObservation::nuisanceNames() const {
    if (!run_.estimateBall) return {};
    return {run_.name + ".xBall", run_.name + ".yBall", run_.name + ".zBall"};
}

void RtestObservation::nuisanceInitial(double* out) const {
    if (run_.estimateBall)
        for (int i = 0; i < 3; ++i) out[i] = run_.ballOffset[i];
}

Vec3 RtestObservation::ball(const double* nuisance) const {
    return run_.ball + (run_.estimateBall ? Vec3(nuisance[0], nuisance[1], nuisance[2]) : run_.ballOffset);
}

void RtestObservation::predict(const Kinematics& k, const double* nuisance, double* out) const {
    const Vec3 b = ball(nuisance);
    const Vec3 nest = k.toolPoint(run_.nestLength);
    for (size_t i = 0; i < commands_.size(); ++i) {
        const Vec3 d = rtestDisplacement(k, commands_[i], b, nest);
        for (int c = 0; c < 3; ++c) out[3 * i + static_cast<size_t>(c)] = d[c];
    }
}

bool RtestObservation::jacobian(const DifferentiableMachine& m, const double* nuisance, const std::vector<int>& flat,
                                Eigen::Ref<Eigen::MatrixXd> J) const {
    const Kinematics& k = m.kinematics();
    const Vec3 b = ball(nuisance);
    const Vec3 nest = k.toolPoint(run_.nestLength);
    const int np = static_cast<int>(flat.size());
    Eigen::MatrixXd jn(3, np), je(3, np);
    for (size_t i = 0; i < commands_.size(); ++i) {
        const Pose wMt = k.workpieceToTool(commands_[i]);
        const Mat3 R = wMt.linear();
        const Vec3 v = b - wMt * nest;
        m.toolPointJacobian(commands_[i], nest, flat, jn);
        const auto row = static_cast<Eigen::Index>(3 * i);
        J.block(row, 0, 3, np) = -R.transpose() * jn;
        for (int c = 0; c < 3; ++c) {
            // ∂(R e_c) = ∂(wMt·(nest + e_c)) − ∂(wMt·nest); row c of (∂R)ᵀ v is vᵀ ∂(R e_c).
            m.toolPointJacobian(commands_[i], nest + Vec3::Unit(c), flat, je);
            J.block(row + c, 0, 1, np) += v.transpose() * (je - jn);
        }
        if (run_.estimateBall) J.block(row, np, 3, 3) = R.transpose();
    }
    return true;
}

Observations rtestObservations(const MachineModel& machine, const std::vector<RtestRun>& runs,
                               const std::vector<RtestTrace>& traces) {
    if (runs.size() != traces.size())
        throw ModelError(fmt::format("{} R-test runs but {} traces", runs.size(), traces.size()));
    Observations obs;
    for (size_t i = 0; i < runs.size(); ++i)
        obs.push_back(std::make_unique<RtestObservation>(machine, runs[i], traces[i]));
    return obs;
}

}  // namespace cnccomp::identification
