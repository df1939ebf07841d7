#pragma once
// Observation model of an absolute ball-bar run (the head patterns of tilting_head_errors.hpp): Ball 2 at its nominal position instead of being set on
// Ball 1 at the setup pose, ΔL = |p_T(q) − p_W| − LB with p_W fixed (see simulateAbsoluteRun).
#include "cnccomp/identification/observation.hpp"

namespace cnccomp::identification {

class AbsoluteBallbarObservation final : public ObservationModel {
public:
    /// `trace` angles may be any subset of the sweep; throws ModelError on size mismatch or non-finite data.
    AbsoluteBallbarObservation(const MachineModel& machine, BallbarRun run, const BallbarTrace& trace);

    std::string runName() const override { return run_.name; }
    std::string kind() const override { return "absolute-ballbar"; }
    int size() const override { return static_cast<int>(measured_.size()); }
    const Eigen::VectorXd& measured() const override { return measured_; }
    /// Nuisance: the work-ball offset (xW yW zW) when run.estimateWorkBallOffset.
    int nuisanceCount() const override { return run_.estimateWorkBallOffset ? 3 : 0; }
    std::vector<std::string> nuisanceNames() const override;
    void nuisanceInitial(double* out) const override;
    void predict(const Kinematics& k, const double* nuisance, double* out) const override;
    bool jacobian(const DifferentiableMachine& m, const double* nuisance, const std::vector<int>& flat,
                  Eigen::Ref<Eigen::MatrixXd> J) const override;

private:
    Vec3 workBall(const double* nuisance) const;

    BallbarRun run_;
    Eigen::VectorXd measured_;
    Vec3 nominalWorkBall_;
    std::vector<AxisVector> commands_;
};

/// One observation per run (same order as the traces).
Observations absoluteBallbarObservations(const MachineModel& machine, const std::vector<BallbarRun>& runs,
                                         const std::vector<BallbarTrace>& traces);

}  // namespace cnccomp::identification
