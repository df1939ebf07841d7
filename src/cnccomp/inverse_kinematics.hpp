#pragma once
// Tool pose of a set of axis commands, its analytic Jacobian, and the inverse: axis commands that put the
// tool tip and tool axis of a (possibly erroneous) machine at a target pose. Newton/Gauss–Newton on the exact model.
#include "cnccomp/kinematics.hpp"

namespace cnccomp {

/// Tool tip position and unit tool axis (spindle → tip), in the workpiece frame.
struct ToolPose {
    Vec3 tip = Vec3::Zero();
    Vec3 axis = -Vec3::UnitZ();
};

using PoseJacobian = Eigen::Matrix<double, 6, Eigen::Dynamic, 0, 6, kMaxAxes>;

/// Pose of the point `tipInToolFrame` (see Kinematics::toolPoint) and of the tool axis.
ToolPose toolPose(const Kinematics& k, const AxisVector& q, const Vec3& tipInToolFrame);

/// d(tip, axis)/dq, 6 × axisCount, workpiece frame; rows 0–2 tip (mm per mm or rad), rows 3–5 axis.
/// Exact for location errors; component errors' own slope is neglected (fine for Newton, tested against
/// finite differences on machines without component errors).
void toolPoseJacobian(const Kinematics& k, const AxisVector& q, const Vec3& tipInToolFrame, PoseJacobian& J);

/// The smallest singular value σ of J's axis rows over the rotary axes of m (rad/rad: the sine of the angle between the
/// tool axis and the rotary axis that cannot turn it; 1 when the machine has no rotary axis): below
/// IkOptions::singularZone the singular-pose policy damps.
double rotarySingularValue(const MachineModel& m, const PoseJacobian& J);

struct IkOptions {
    double tolerance = 1e-9;     ///< mm on the tip, and rad × axisWeight on the axis
    int maxIterations = 30;
    double axisWeight = 100.0;   ///< mm per rad: how much an axis error counts against a tip error
    /// mm per rad: pull of every rotary axis towards its start value. Keeps the solution next to the commanded one
    /// where the tool axis cannot be matched: with the tool axis parallel to a rotary axis (B = 0 on a mill-turn
    /// machine) a tilt of ε could only be removed by turning C by up to 90°; with this pull the solver leaves C alone
    /// for tilts below regularization/axisWeight (1e-3 rad) and still meets the tip exactly (the slides can).
    /// Away from such poses it costs a relative (regularization/axisWeight)² = 1e-6 of the axis correction.
    double rotaryRegularization = 0.1;
    /// With singularZone > 0 the pull acts only near a singular pose and only in the directions that cannot turn the
    /// tool axis: the singular-pose policy of pose_solver.hpp, SingularPosePolicy{rotaryRegularization, singularZone},
    /// the damping D = λ² Σ φ(σᵢ) vᵢ vᵢᵀ of the rotary axes, σᵢ and vᵢ the singular values and right singular vectors
    /// of the tool axis' derivative over the rotary axes (rad/rad), φ(σ) = (1 − σ/singularZone)² below the zone and 0
    /// above it (this shape is cnccomp's [G]): damped least squares with variable damping [NakamuraHanafusa1986],
    /// [Chiaverini1994] in the ill-conditioned directions only [MaciejewskiKlein1988] (README, References). Away from
    /// singular poses the axis is met exactly (no pull, no floor); a direction that cannot turn the tool axis at all
    /// (σ = 0) is pulled with the full λ; across a singular pose the rotary axes turn smoothly, for a tool-axis error
    /// δ by at most about max over σ of w²σδ / (w²σ² + λ²φ(σ)), w = axisWeight: 1.21·δ/singularZone with
    /// λ = w·singularZone (the LinuxCNC component's choice), δ/σ outside the zone. 0: the constant pull above (φ ≡ 1).
    double singularZone = 0.0;
    /// After the pulled solution, up to 4 steps without the pull where they lower the cost and swing no rotary axis by
    /// regularization/axisWeight or more: regular poses then meet the axis fully. With singularZone > 0 the pulled
    /// solution is already exact outside the zone, and inside it a polish step would take back the policy's damping
    /// wherever it swings the rotary axes by less than that bound. Off, the solution is a smooth function of the
    /// target (no switch between polished and unpolished near a singular pose), as a joint trajectory needs (the
    /// LinuxCNC kinematics component, controllers/linuxcnc/kins_component.hpp).
    bool polish = true;
};

struct IkResult {
    AxisVector q;
    double tipError = 0.0;   ///< mm
    double axisError = 0.0;  ///< rad
    int iterations = 0;
    bool converged = false;
};

/// Axis commands near `start` at which machine `k` puts its tool at `target`: Gauss–Newton on
/// |tip error|² + axisWeight²·|axis error|² + regularization²·|rotary − start|². The tip is met exactly whenever the
/// slides can reach it; where the axis cannot be matched (too few axes, singular pose) the result is the
/// least-squares compromise closest to the commanded rotary positions. `converged` says the iteration settled.
IkResult solveToolPose(const Kinematics& k, const ToolPose& target, const Vec3& tipInToolFrame, const AxisVector& start,
                       const IkOptions& options = {});

}  // namespace cnccomp
