#pragma once
// The least-squares problem: stacked weighted residuals r = w · (measured − predicted) of every observation and
// their Jacobian with respect to the scaled unknowns (UnknownLayout). Deviations that are not estimated keep the
// values of the `fixed` set.
#include "cnccomp/identification/parameters.hpp"

namespace cnccomp::identification {

class LsqProblem {
public:
    /// `fixed`: values of every deviation (estimated ones give the starting point).
    LsqProblem(const MachineModel& machine, const Observations& observations, const UnknownLayout& layout,
               const DeviationSet& fixed);

    const UnknownLayout& layout() const { return *layout_; }
    const Observations& observations() const { return *observations_; }
    int rows() const { return rows_; }
    int cols() const { return layout_->size(); }
    /// First residual row of observation r.
    int rowStart(int r) const { return rowStart_[r]; }
    /// Scaled starting point (estimated deviations from `fixed`, nuisance from the observations).
    const Eigen::VectorXd& start() const { return start_; }

    /// Deviation set at scaled point x (fixed deviations plus the estimated ones).
    DeviationSet deviations(const Eigen::VectorXd& x) const;
    /// Nuisance vector (internal units) at scaled point x.
    Eigen::VectorXd nuisance(const Eigen::VectorXd& x) const;

    /// Stacked predictions (unweighted, internal units).
    void predict(const Eigen::VectorXd& x, Eigen::VectorXd& out) const;
    /// Residuals w·(measured − predicted).
    void residuals(const Eigen::VectorXd& x, Eigen::VectorXd& r) const;
    /// ∂r/∂x (rows × cols): analytic where the observation provides it, else central differences.
    void jacobian(const Eigen::VectorXd& x, Eigen::MatrixXd& J) const;
    /// ∂r/∂x by central differences of predict() for every observation (the reference for tests).
    void numericJacobian(const Eigen::VectorXd& x, Eigen::MatrixXd& J, double step = 1e-2) const;

    /// Replaces the measured values (e.g. for Monte Carlo resampling); empty = the observations' own values.
    void setMeasured(const Eigen::VectorXd& measured);
    const Eigen::VectorXd& measured() const { return measured_; }
    const Eigen::VectorXd& weights() const { return weights_; }

private:
    void numericBlock(const Eigen::VectorXd& x, int r, Eigen::MatrixXd& J, double step) const;

    const MachineModel* machine_;
    const Observations* observations_;
    const UnknownLayout* layout_;
    DeviationSet fixed_;
    int rows_ = 0;
    std::vector<int> rowStart_;
    Eigen::VectorXd start_, measured_, weights_;
};

}  // namespace cnccomp::identification
