#pragma once
// Observations of a plan's measured runs: the ball-bar traces through the trace import (io/trace_import.hpp, checked
// against their runs), with a bar-length offset per run for relative instruments, and every other kind of run as
// planObservations() reads it.
#include <memory>
#include <string>
#include <vector>

#include "cnccomp/identification/observation.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "cnccomp/measurement/plan_measurements.hpp"
#include "cnccomp/io/trace_import.hpp"

namespace cnccomp::identification {

/// A ball-bar run recorded by an instrument that does not know its absolute length (a relative transducer zeroed
/// anywhere): measured ΔL = ΔL_model + dL0. Wraps the run's observation and adds the offset dL0 as one more
/// nuisance parameter "<run>.dL0" (a length, starting at 0); its Jacobian column is all ones.
class LengthOffsetObservation final : public ObservationModel {
public:
    explicit LengthOffsetObservation(std::unique_ptr<ObservationModel> inner);

    std::string runName() const override { return inner_->runName(); }
    std::string kind() const override { return inner_->kind(); }
    int size() const override { return inner_->size(); }
    const Eigen::VectorXd& measured() const override { return inner_->measured(); }
    double weight() const override { return inner_->weight(); }
    int nuisanceCount() const override { return inner_->nuisanceCount() + 1; }
    std::vector<std::string> nuisanceNames() const override;
    void nuisanceInitial(double* out) const override;
    double nuisanceScale(int i) const override;
    void predict(const Kinematics& k, const double* nuisance, double* out) const override;
    bool jacobian(const DifferentiableMachine& m, const double* nuisance, const std::vector<int>& flat,
                  Eigen::Ref<Eigen::MatrixXd> J) const override;
    std::vector<double> sweepAnglesDeg() const override { return inner_->sweepAnglesDeg(); }
    std::vector<std::string> turningAxes() const override { return inner_->turningAxes(); }
    bool movesOnlyLinearAxes() const override { return inner_->movesOnlyLinearAxes(); }

private:
    std::unique_ptr<ObservationModel> inner_;
};

struct MeasuredRuns {
    std::vector<io::MeasuredTrace> ballbar;  ///< one per plan.runs entry, same order (passes, import summary)
    Observations observations;           ///< plan.runs first (same order), then the other kinds as planObservations
};

/// The observations of the plan's captures read once (io/plan_measurements_io.hpp, MeasurementKinds::observed(): the
/// ball-bar files imported with their capture settings, `# machine:` lines checked against machine.name): wraps the
/// runs whose instrument is relative, and adds the plan's other runs (planObservations).
MeasuredRuns measuredObservations(const MachineModel& machine, const measurement::MeasurementPlan& plan, const measurement::PlanMeasurements& data);

}  // namespace cnccomp::identification
