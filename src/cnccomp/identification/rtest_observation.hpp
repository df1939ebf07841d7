#pragma once
// Observation model of an R-test run for the least-squares engine: the three displacement components of the ball
// centre from the nest centre, in the tool (sensor) frame, at every pose (rtestDisplacement). Nuisance: the ball's
// mounting offset (3 values) when the run says estimate-ball.
#include "cnccomp/identification/observation.hpp"
#include "cnccomp/identification/rtest_run.hpp"

namespace cnccomp::identification {

class RtestObservation final : public ObservationModel {
public:
    /// `trace.commands` are the poses (rtestCommands); throws ModelError on size mismatch or non-finite data.
    RtestObservation(const MachineModel& machine, measurement::RtestRun run, const RtestTrace& trace);

    std::string runName() const override { return run_.name; }
    std::string kind() const override { return "rtest"; }
    int size() const override { return static_cast<int>(measured_.size()); }
    const Eigen::VectorXd& measured() const override { return measured_; }
    int nuisanceCount() const override { return run_.estimateBall ? 3 : 0; }
    std::vector<std::string> nuisanceNames() const override;
    void nuisanceInitial(double* out) const override;
    void predict(const Kinematics& k, const double* nuisance, double* out) const override;
    /// Exact: ∂d = Rᵀ(−∂n) + (∂R)ᵀ(b − n), n = wMt·nest, R its rotation, ∂R from tool-point Jacobians.
    bool jacobian(const DifferentiableMachine& m, const double* nuisance, const std::vector<int>& flat,
                  Eigen::Ref<Eigen::MatrixXd> J) const override;

    const measurement::RtestRun& run() const { return run_; }

private:
    Vec3 ball(const double* nuisance) const;

    measurement::RtestRun run_;
    Eigen::VectorXd measured_;
    std::vector<AxisVector> commands_;
};

/// One observation per run (same order as the traces).
Observations rtestObservations(const MachineModel& machine, const std::vector<measurement::RtestRun>& runs,
                               const std::vector<RtestTrace>& traces);

}  // namespace cnccomp::identification
