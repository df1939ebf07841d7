#include "cnccomp/identification/absolute_ballbar_observation.hpp"

#include <cmath>

#include <fmt/format.h>

#include "cnccomp/error.hpp"

namespace cnccomp::identification {

AbsoluteBallbarObservation::AbsoluteBallbarObservation(const MachineModel& machine, BallbarRun run,
                                                       const BallbarTrace& trace)
    : run_(std::move(run)) {
    run_.validate();
    if (trace.angleDeg.size() != trace.dL.size() || trace.dL.empty())
        throw ModelError(fmt::format("run '{}': trace has {} angles and {} ΔL values", run_.name, trace.angleDeg.size(),
                                     trace.dL.size()));
    const Kinematics nominal(machine);
    const AxisVector setup = setupCommands(machine, run_);
    nominalWorkBall_ = nominal.toolPointInWorkpiece(setup, nominal.toolPoint(run_.RB, run_.toolBallOffset));
    measured_.resize(static_cast<Eigen::Index>(trace.dL.size()));
    for (size_t i = 0; i < trace.dL.size(); ++i) {
        if (!std::isfinite(trace.angleDeg[i]) || !std::isfinite(trace.dL[i]))
            throw ModelError(fmt::format("run '{}': sample {} is not a finite number", run_.name, i + 1));
        measured_[static_cast<Eigen::Index>(i)] = trace.dL[i];
        const AxisVector q = runCommands(machine, run_, trace.angleDeg[i] * kDeg);
        try {
            nominal.checkTravel(q);
        } catch (const ModelError& e) {
            throw ModelError(fmt::format("run '{}' at {:g} deg: {}", run_.name, trace.angleDeg[i], e.what()));
        }
        commands_.push_back(q);
    }
}

std::vector<std::string> AbsoluteBallbarObservation::nuisanceNames() const {
    if (!run_.estimateWorkBallOffset) return {};
    return {run_.name + ".xW", run_.name + ".yW", run_.name + ".zW"};
}

void AbsoluteBallbarObservation::nuisanceInitial(double* out) const {
    if (run_.estimateWorkBallOffset)
        for (int i = 0; i < 3; ++i) out[i] = run_.workBallOffset[i];
}

Vec3 AbsoluteBallbarObservation::workBall(const double* nuisance) const {
    const Vec3 off = run_.estimateWorkBallOffset ? Vec3(nuisance[0], nuisance[1], nuisance[2]) : run_.workBallOffset;
    return nominalWorkBall_ + off;
}

void AbsoluteBallbarObservation::predict(const Kinematics& k, const double* nuisance, double* out) const {
    const Vec3 tBall = k.toolPoint(run_.RB, run_.toolBallOffset);
    const Vec3 wBall = workBall(nuisance);
    for (size_t i = 0; i < commands_.size(); ++i)
        out[i] = (k.toolPointInWorkpiece(commands_[i], tBall) - wBall).norm() - run_.LB;
}

bool AbsoluteBallbarObservation::jacobian(const DifferentiableMachine& m, const double* nuisance,
                                          const std::vector<int>& flat, Eigen::Ref<Eigen::MatrixXd> J) const {
    const Kinematics& k = m.kinematics();
    const Vec3 tBall = k.toolPoint(run_.RB, run_.toolBallOffset);
    const Vec3 wBall = workBall(nuisance);
    const int np = static_cast<int>(flat.size());
    Eigen::MatrixXd ji(3, np);
    for (size_t i = 0; i < commands_.size(); ++i) {
        const Vec3 d = k.toolPointInWorkpiece(commands_[i], tBall) - wBall;
        const Vec3 n = d / d.norm();
        m.toolPointJacobian(commands_[i], tBall, flat, ji);
        const auto row = static_cast<Eigen::Index>(i);
        J.row(row).head(np) = n.transpose() * ji;
        if (run_.estimateWorkBallOffset) J.row(row).segment<3>(np) = -n.transpose();
    }
    return true;
}

Observations absoluteBallbarObservations(const MachineModel& machine, const std::vector<BallbarRun>& runs,
                                         const std::vector<BallbarTrace>& traces) {
    if (runs.size() != traces.size())
        throw ModelError(fmt::format("{} absolute runs but {} traces", runs.size(), traces.size()));
    Observations obs;
    for (size_t i = 0; i < runs.size(); ++i)
        obs.push_back(std::make_unique<AbsoluteBallbarObservation>(machine, runs[i], traces[i]));
    return obs;
}

}  // namespace cnccomp::identification
