#pragma once
// The eccentricity of a ball-bar run as an observation (the quantity [MultiTasking] section 4 works with): the in-plane
// centre (u, v components, RunPlane) of the least-squares circle fitted to the trace, predicted by simulating the
// run on the current machine and fitting the same circle. Least squares on eccentricities generalises the
// closed-form formulas (17)–(28) to any set of runs, and lets the planner reproduce [MultiTasking]'s reasoning
// (e.g. γXY moves only the eccentricity of the C-axis Y-direction run, Table 3).
// Weight √(N/2): the centre of a circle fitted to N samples of noise σ has a standard deviation σ·√(2/N), so the
// residuals are in units of ΔL noise like those of BallbarObservation. No analytic Jacobian (finite differences).
#include "cnccomp/identification/observation.hpp"

namespace cnccomp::identification {

class EccentricityObservation final : public ObservationModel {
public:
    /// `trace`: the measured run (its angles are simulated for the prediction). Throws ModelError for < 3 samples.
    EccentricityObservation(const MachineModel& machine, BallbarRun run, const BallbarTrace& trace);

    std::string runName() const override { return run_.name; }
    std::string kind() const override { return "eccentricity"; }
    int size() const override { return 2; }
    const Eigen::VectorXd& measured() const override { return measured_; }
    double weight() const override { return weight_; }
    void predict(const Kinematics& k, const double* nuisance, double* out) const override;

private:
    BallbarRun run_;
    std::vector<double> anglesDeg_;
    Eigen::VectorXd measured_;
    double weight_ = 1;
    RunPlane plane_;
};

/// One EccentricityObservation per run.
Observations eccentricityObservations(const MachineModel& machine, const std::vector<BallbarRun>& runs,
                                      const std::vector<BallbarTrace>& traces);

}  // namespace cnccomp::identification
