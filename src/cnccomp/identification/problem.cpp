#include "cnccomp/identification/problem.hpp"

#include <cmath>

#include <fmt/format.h>

#include "cnccomp/error.hpp"

namespace cnccomp::identification {

LsqProblem::LsqProblem(const MachineModel& machine, const Observations& observations, const UnknownLayout& layout,
                       const DeviationSet& fixed)
    : machine_(&machine), observations_(&observations), layout_(&layout), fixed_(fixed) {
    if (observations.empty()) throw ModelError("identification needs at least one measured run");
    if (fixed.values.size() != machine.parameterCount())
        throw ModelError(fmt::format("deviation set does not fit machine '{}'", machine.name));
    for (const auto& o : observations) {
        rowStart_.push_back(rows_);
        rows_ += o->size();
    }
    measured_.resize(rows_);
    weights_.resize(rows_);
    Eigen::VectorXd nuis(layout.size() - layout.deviationUnknowns());
    for (size_t r = 0; r < observations.size(); ++r) {
        const ObservationModel& o = *observations[r];
        if (o.measured().size() != o.size())
            throw ModelError(fmt::format("run '{}': {} measured values for {} observations", o.runName(),
                                         o.measured().size(), o.size()));
        if (!o.measured().allFinite()) throw ModelError(fmt::format("run '{}': measured values must be finite", o.runName()));
        if (!(o.weight() > 0) || !std::isfinite(o.weight()))
            throw ModelError(fmt::format("run '{}': weight must be positive", o.runName()));
        measured_.segment(rowStart_[r], o.size()) = o.measured();
        weights_.segment(rowStart_[r], o.size()).setConstant(o.weight());
        if (o.nuisanceCount() > 0)
            o.nuisanceInitial(nuis.data() + (layout.nuisanceStart(static_cast<int>(r)) - layout.deviationUnknowns()));
    }
    start_ = layout.pack(fixed_, nuis);
}

DeviationSet LsqProblem::deviations(const Eigen::VectorXd& x) const {
    DeviationSet d = fixed_;
    Eigen::VectorXd nuis(layout_->size() - layout_->deviationUnknowns());
    layout_->unpack(x, d, nuis);
    return d;
}

Eigen::VectorXd LsqProblem::nuisance(const Eigen::VectorXd& x) const {
    DeviationSet d = fixed_;
    Eigen::VectorXd nuis(layout_->size() - layout_->deviationUnknowns());
    layout_->unpack(x, d, nuis);
    return nuis;
}

void LsqProblem::predict(const Eigen::VectorXd& x, Eigen::VectorXd& out) const {
    DeviationSet d = fixed_;
    Eigen::VectorXd nuis(layout_->size() - layout_->deviationUnknowns());
    layout_->unpack(x, d, nuis);
    const Kinematics k(*machine_, d);
    out.resize(rows_);
    const int nd = layout_->deviationUnknowns();
    for (size_t r = 0; r < observations_->size(); ++r) {
        const ObservationModel& o = *(*observations_)[r];
        o.predict(k, nuis.data() + (layout_->nuisanceStart(static_cast<int>(r)) - nd), out.data() + rowStart_[r]);
    }
}

void LsqProblem::residuals(const Eigen::VectorXd& x, Eigen::VectorXd& r) const {
    predict(x, r);
    r = weights_.cwiseProduct(measured_ - r);
}

void LsqProblem::numericBlock(const Eigen::VectorXd& x, int r, Eigen::MatrixXd& J, double step) const {
    // Central differences of one observation's predictions over every unknown it depends on.
    const ObservationModel& o = *(*observations_)[r];
    const int nd = layout_->deviationUnknowns();
    const int n0 = layout_->nuisanceStart(r);
    Eigen::VectorXd plus(o.size()), minus(o.size());
    for (int c = 0; c < cols(); ++c) {
        const UnknownInfo& u = (*layout_)[c];
        if (u.nuisance && u.run != r) continue;
        for (int sgn : {1, -1}) {
            Eigen::VectorXd xs = x;
            xs[c] += sgn * step;
            DeviationSet d = fixed_;
            Eigen::VectorXd nuis(layout_->size() - nd);
            layout_->unpack(xs, d, nuis);
            const Kinematics k(*machine_, d);
            o.predict(k, nuis.data() + (n0 - nd), (sgn > 0 ? plus : minus).data());
        }
        J.block(rowStart_[r], c, o.size(), 1) = -o.weight() * (plus - minus) / (2 * step);
    }
}

void LsqProblem::numericJacobian(const Eigen::VectorXd& x, Eigen::MatrixXd& J, double step) const {
    J.setZero(rows_, cols());
    for (int r = 0; r < static_cast<int>(observations_->size()); ++r) numericBlock(x, r, J, step);
}

void LsqProblem::jacobian(const Eigen::VectorXd& x, Eigen::MatrixXd& J) const {
    J.setZero(rows_, cols());
    const int nd = layout_->deviationUnknowns();
    DeviationSet d = fixed_;
    Eigen::VectorXd nuis(layout_->size() - nd);
    layout_->unpack(x, d, nuis);
    const DifferentiableMachine dm(*machine_, d);
    Eigen::RowVectorXd scale(cols());
    for (int c = 0; c < cols(); ++c) scale[c] = (*layout_)[c].scale;
    for (int r = 0; r < static_cast<int>(observations_->size()); ++r) {
        const ObservationModel& o = *(*observations_)[r];
        const int nn = o.nuisanceCount(), n0 = layout_->nuisanceStart(r);
        const int nf = static_cast<int>(layout_->flat().size());
        Eigen::MatrixXd block(o.size(), nf + nn);
        if (!o.jacobian(dm, nuis.data() + (n0 - nd), layout_->flat(), block)) {
            numericBlock(x, r, J, 1e-2);
            continue;
        }
        // d r / d x_scaled = −w · ∂pred/∂(link values) · ∂(link values)/∂(unknowns) · scale
        J.block(rowStart_[r], 0, o.size(), nd) =
            -o.weight() * (block.leftCols(nf) * layout_->transform()) * scale.head(nd).asDiagonal();
        if (nn > 0)
            J.block(rowStart_[r], n0, o.size(), nn) =
                -o.weight() * block.rightCols(nn) * scale.segment(n0, nn).asDiagonal();
    }
}

void LsqProblem::setMeasured(const Eigen::VectorXd& measured) {
    if (measured.size() == 0) {
        for (size_t r = 0; r < observations_->size(); ++r)
            measured_.segment(rowStart_[r], (*observations_)[r]->size()) = (*observations_)[r]->measured();
        return;
    }
    if (measured.size() != rows_) throw ModelError("resampled measurement vector has the wrong size");
    measured_ = measured;
}

}  // namespace cnccomp::identification
