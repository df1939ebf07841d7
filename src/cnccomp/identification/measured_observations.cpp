#include "cnccomp/identification/measured_observations.hpp"

#include "cnccomp/error.hpp"
#include "cnccomp/identification/plan_observations.hpp"

namespace cnccomp::identification {
using namespace cnccomp::measurement;

LengthOffsetObservation::LengthOffsetObservation(std::unique_ptr<ObservationModel> inner) : inner_(std::move(inner)) {}

std::vector<std::string> LengthOffsetObservation::nuisanceNames() const {
    std::vector<std::string> n = inner_->nuisanceNames();
    n.push_back(inner_->runName() + ".dL0");
    return n;
}

void LengthOffsetObservation::nuisanceInitial(double* out) const {
    inner_->nuisanceInitial(out);
    out[inner_->nuisanceCount()] = 0.0;
}

double LengthOffsetObservation::nuisanceScale(int i) const {
    return i < inner_->nuisanceCount() ? inner_->nuisanceScale(i) : kUm;
}

void LengthOffsetObservation::predict(const Kinematics& k, const double* nuisance, double* out) const {
    inner_->predict(k, nuisance, out);
    const double offset = nuisance[inner_->nuisanceCount()];
    for (int i = 0; i < size(); ++i) out[i] += offset;
}

bool LengthOffsetObservation::jacobian(const DifferentiableMachine& m, const double* nuisance, const std::vector<int>& flat,
                                       Eigen::Ref<Eigen::MatrixXd> J) const {
    const Eigen::Index inner = static_cast<Eigen::Index>(flat.size()) + inner_->nuisanceCount();
    if (!inner_->jacobian(m, nuisance, flat, J.leftCols(inner))) return false;
    J.col(inner).setOnes();
    return true;
}

MeasuredRuns measuredObservations(const MachineModel& machine, const MeasurementPlan& plan, const PlanMeasurements& data) {
    MeasuredRuns out;
    if (!plan.runs.empty() && (!data.loaded.ballbar || data.ballbar.size() != plan.runs.size()))
        throw ModelError("the measurements of the plan's ball-bar runs were not read");
    out.ballbar = data.ballbar;
    for (size_t i = 0; i < plan.runs.size(); ++i) {
        std::unique_ptr<ObservationModel> o =
            std::make_unique<BallbarObservation>(machine, plan.runs[i], out.ballbar[i].trace);
        if (plan.runs[i].capture.relativeLength) o = std::make_unique<LengthOffsetObservation>(std::move(o));
        out.observations.push_back(std::move(o));
    }
    MeasurementPlan rest = plan;
    rest.runs.clear();
    if (rest.runCount() > 0)
        for (auto& o : planObservations(machine, rest, data)) out.observations.push_back(std::move(o));
    return out;
}

}  // namespace cnccomp::identification
