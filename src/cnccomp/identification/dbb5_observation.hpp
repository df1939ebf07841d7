#pragma once
// Observation model of a DBB5 run (Ibaraki et al., dbb5_run.hpp) for the least-squares engine: raw ΔL samples,
// predicted exactly as simulateDbb5() does (table ball set on the spindle ball at the setup pose, then ΔL along the
// sweep).
#include "cnccomp/identification/dbb5_run.hpp"
#include "cnccomp/identification/observation.hpp"

namespace cnccomp::identification {

class Dbb5Observation final : public ObservationModel {
public:
    /// `trace` angles may be any subset of the sweep; throws ModelError on size mismatch or non-finite data.
    Dbb5Observation(const MachineModel& machine, measurement::Dbb5Run run, const BallbarTrace& trace);

    std::string runName() const override { return run_.name; }
    std::string kind() const override { return "dbb5"; }
    int size() const override { return static_cast<int>(measured_.size()); }
    const Eigen::VectorXd& measured() const override { return measured_; }
    void predict(const Kinematics& k, const double* nuisance, double* out) const override;
    /// ∂ΔL = uᵀ(∂p(q) − ∂p(q_setup)), u the unit bar vector, p the spindle ball seen from the workpiece.
    bool jacobian(const DifferentiableMachine& m, const double* nuisance, const std::vector<int>& flat,
                  Eigen::Ref<Eigen::MatrixXd> J) const override;

    std::vector<double> sweepAnglesDeg() const override { return anglesDeg_; }
    /// The turning axis of a rotary circle; every rotary axis the machine moves in a cone frustum; none for linear circles.
    std::vector<std::string> turningAxes() const override { return turning_; }
    bool movesOnlyLinearAxes() const override { return run_.kind == measurement::Dbb5Run::Kind::LinearCircle; }

    const measurement::Dbb5Run& run() const { return run_; }

private:
    measurement::Dbb5Run run_;
    Eigen::VectorXd measured_;
    std::vector<double> anglesDeg_;
    std::vector<std::string> turning_;
    AxisVector setup_;
    std::vector<AxisVector> commands_;
};

/// One observation per run (same order as the traces).
Observations dbb5Observations(const MachineModel& machine, const std::vector<measurement::Dbb5Run>& runs,
                              const std::vector<BallbarTrace>& traces);

}  // namespace cnccomp::identification
