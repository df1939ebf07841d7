#pragma once
// Observation models for the general least-squares identification.
//
// HOW ANOTHER OBSERVATION KIND PLUGS IN (R-test ball displacements, DBB5 circles, probe points, ...):
//   1. Derive from ObservationModel, one object per measured run. Keep the measured values (internal units,
//      mm / rad) in a member and return them from measured(); size() is their count.
//   2. predict(k, nuisance, out): write size() predicted values for the machine `k` (exact kinematics built
//      by the engine from the current deviation vector) and the run's own nuisance parameters (`nuisance`
//      points at nuisanceCount() values, e.g. sensor mounting offsets). The engine minimises
//      Σ_runs Σ_i (weight · (measured_i − predicted_i))².
//   3. Nuisance parameters (per run, estimated with the deviations): nuisanceCount(), nuisanceNames()
//      ("<run>.xT"), nuisanceInitial() (the value the plan gives), nuisanceScale() (typical size: kUm for a
//      length, kArcsec for an angle; the solver works in these units so the problem is well conditioned).
//   4. Jacobian (optional but much faster): override jacobian() and fill d(predicted)/d(parameter) for the
//      requested flat deviation indices followed by the nuisance parameters. DifferentiableMachine gives
//      the exact derivative of any tool point seen from the workpiece (toolPointJacobian) and of any point
//      fixed on either chain (bedPointJacobian). Returning false makes the engine use central finite
//      differences on predict(). tests/core/identification/test_lsq_jacobian.cpp checks every analytic Jacobian against them:
//      add a case there for a new kind.
//   5. Build the observations of a plan with a factory (see ballbarObservations below) and hand them to
//      identify() (identification/lsq.hpp) as std::vector<std::unique_ptr<ObservationModel>>.
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "cnccomp/ballbar.hpp"
#include "cnccomp/deviations.hpp"
#include "cnccomp/kinematics.hpp"

namespace cnccomp::identification {

/// The machine at one deviation vector: its exact kinematics plus exact first derivatives of chain points
/// with respect to the flat deviation vector (location and component errors, rotation parts through the
/// exact left Jacobian of SO(3) so that they agree with finite differences of Kinematics).
class DifferentiableMachine {
public:
    DifferentiableMachine(const MachineModel& machine, const DeviationSet& deviations);
    DifferentiableMachine(const DifferentiableMachine&) = delete;
    DifferentiableMachine& operator=(const DifferentiableMachine&) = delete;

    const MachineModel& machine() const { return *machine_; }
    const Kinematics& kinematics() const { return kinematics_; }
    const DeviationSet& deviations() const { return deviations_; }

    /// out(:, j) = ∂p/∂values[flat[j]], p = the point fixed in the tool frame `toolPoint` seen from the
    /// workpiece frame at commands q (Kinematics::toolPointInWorkpiece). `out` is 3 × flat.size().
    void toolPointJacobian(const AxisVector& q, const Vec3& toolPoint, const std::vector<int>& flat,
                           Eigen::Ref<Eigen::MatrixXd> out) const;
    /// out(:, j) = ∂(bed coordinates of a point fixed at the end of chain `side`)/∂values[flat[j]].
    void bedPointJacobian(Side side, const AxisVector& q, const Vec3& pointInEndFrame, const std::vector<int>& flat,
                          Eigen::Ref<Eigen::MatrixXd> out) const;

private:
    struct FlatOwner {
        int deviation = -1;  ///< index into machine.deviations
        int coefficient = 0;
    };
    struct LinkConstants {
        Vec6 location = Vec6::Zero();  ///< summed location errors of the link
        Mat3 locationJl = Mat3::Identity();  ///< left Jacobian of SO(3) at the location rotation
        bool hasComponent = false;
    };
    struct Frames;
    void chainFrames(Side side, const AxisVector& q, Frames& f) const;
    void chainDerivative(Side side, const Frames& f, const Vec3& pBed, int flat, Vec3& out) const;

    const MachineModel* machine_;
    DeviationSet deviations_;
    Kinematics kinematics_;
    std::vector<FlatOwner> owner_;
    std::vector<LinkConstants> tool_, workpiece_;
};

/// One measured run as seen by the least-squares engine. Residual = measured − predicted.
class ObservationModel {
public:
    virtual ~ObservationModel() = default;
    /// Run name (from the plan), used in the report.
    virtual std::string runName() const = 0;
    /// Observation kind ("ballbar", "rtest", "dbb5", ...), used in the report.
    virtual std::string kind() const = 0;
    /// Number of scalar observations.
    virtual int size() const = 0;
    /// Measured values, internal units (mm / rad), size().
    virtual const Eigen::VectorXd& measured() const = 0;
    /// Residual weight (1 / expected noise in the units of the other kinds); 1 for every ball-bar sample.
    virtual double weight() const { return 1.0; }

    virtual int nuisanceCount() const { return 0; }
    virtual std::vector<std::string> nuisanceNames() const { return {}; }
    /// Starting values of the nuisance parameters (internal units), nuisanceCount() values.
    virtual void nuisanceInitial(double* /*out*/) const {}
    /// Typical size of nuisance parameter i (kUm for a length, kArcsec for an angle).
    virtual double nuisanceScale(int /*i*/) const { return kUm; }

    /// Predicted values for the machine `k` and this run's nuisance parameters; writes size() values.
    virtual void predict(const Kinematics& k, const double* nuisance, double* out) const = 0;

    /// Analytic Jacobian of predict(): J is size() × (flat.size() + nuisanceCount()), columns in the order
    /// of `flat` (indices into the deviation vector) then the nuisance parameters. Return false when not
    /// implemented: the engine then differentiates predict() numerically.
    virtual bool jacobian(const DifferentiableMachine& /*m*/, const double* /*nuisance*/,
                          const std::vector<int>& /*flat*/, Eigen::Ref<Eigen::MatrixXd> /*J*/) const {
        return false;
    }

    /// Model adequacy (identification/adequacy.hpp): the sweep angle of every sample in degrees, in recording order
    /// (empty for runs without one sweep, e.g. R-test poses); samples at equal angles are repeats (passes).
    virtual std::vector<double> sweepAnglesDeg() const { return {}; }
    /// Rotary axes that turn during the run (their component errors are what a residual pattern over the sweep
    /// angle points to); empty when only linear axes move.
    virtual std::vector<std::string> turningAxes() const { return {}; }
    /// True only for a run known to move the linear axes alone, every rotary axis held (a circle in a plane of two
    /// linear axes): what it determines is fitted from such runs first (identification/staged_fit.hpp). False when
    /// not known.
    virtual bool movesOnlyLinearAxes() const { return false; }
};

using Observations = std::vector<std::unique_ptr<ObservationModel>>;

/// Raw ΔL samples of one ball-bar run ([MultiTasking] eq. (14)–(16)), predicted exactly as simulateRun() does:
/// the W-side ball set where the T-side ball is at the setup commands, then ΔL at every sample angle.
/// Nuisance parameters: the tool-ball offset (xT yT zT, eq. (15)) when run.estimateToolBallOffset, the
/// work-ball offset (xW yW zW, eq. (16)) when run.estimateWorkBallOffset.
class BallbarObservation final : public ObservationModel {
public:
    /// `trace` angles may be any subset of the sweep; throws ModelError on size mismatch or non-finite data.
    BallbarObservation(const MachineModel& machine, BallbarRun run, const BallbarTrace& trace);

    std::string runName() const override { return run_.name; }
    std::string kind() const override { return "ballbar"; }
    int size() const override { return static_cast<int>(measured_.size()); }
    const Eigen::VectorXd& measured() const override { return measured_; }
    int nuisanceCount() const override;
    std::vector<std::string> nuisanceNames() const override;
    void nuisanceInitial(double* out) const override;
    void predict(const Kinematics& k, const double* nuisance, double* out) const override;
    bool jacobian(const DifferentiableMachine& m, const double* nuisance, const std::vector<int>& flat,
                  Eigen::Ref<Eigen::MatrixXd> J) const override;

    std::vector<double> sweepAnglesDeg() const override { return anglesDeg_; }
    std::vector<std::string> turningAxes() const override;
    const BallbarRun& run() const { return run_; }
    const std::vector<AxisVector>& commands() const { return commands_; }

private:
    /// Tool-ball and work-ball offsets after applying the nuisance values.
    void offsets(const double* nuisance, Vec3& tool, Vec3& work) const;

    BallbarRun run_;
    Eigen::VectorXd measured_;
    std::vector<double> anglesDeg_;
    AxisVector setup_;
    std::vector<AxisVector> commands_;
};

/// One BallbarObservation per run of a plan, from the traces read for it (same order).
Observations ballbarObservations(const MachineModel& machine, const std::vector<BallbarRun>& runs,
                                 const std::vector<BallbarTrace>& traces);

}  // namespace cnccomp::identification
