#pragma once
// Exact forward kinematics of a machine with a deviation set (full rotation matrices, no small-angle
// truncation). [MultiTasking]: the tool chain reproduces T = E_Z M_YZ E_Y M_XY E_X M_XB E_B M_BT T_T (eq. (7)),
// the workpiece chain W = M_CZ E_C W_C (eq. (10)).
// There is one chain walk: this class is the kinematics engine (kinematics_engine.hpp) compiled with
// Arithmetic::AsExactModel and evaluated without a workspace (KinematicsModel::chainFrame), for callers that evaluate
// single poses (simulation, identification, the controllers' apply models, verify); the map and `correct` hold the
// same engine's model with a workspace of their own.
#include "cnccomp/deviations.hpp"
#include "cnccomp/kinematics_engine.hpp"
#include "cnccomp/machine.hpp"

namespace cnccomp {

/// A machine with its deviations folded into per-link constant transforms. Cheap to evaluate:
/// no allocation per call, safe to share between threads.
class Kinematics {
public:
    /// Nominal machine (all deviations zero).
    explicit Kinematics(const MachineModel& machine);
    /// Erroneous machine.
    Kinematics(const MachineModel& machine, const DeviationSet& deviations);

    const MachineModel& machine() const { return model_.machine(); }
    /// The engine's model this evaluates (Arithmetic::AsExactModel): for a workspace of one's own, bit for bit the same.
    const KinematicsModel& model() const { return model_; }

    /// bMw: pose of the workpiece frame (after the last workpiece-side link) in the bed frame.
    Pose baseToWorkpiece(const AxisVector& q) const;
    /// bMt: pose of the tool frame (after the last tool-side link) in the bed frame.
    Pose baseToTool(const AxisVector& q) const;
    /// wMt = bMw⁻¹ · bMt.
    Pose workpieceToTool(const AxisVector& q) const;
    /// A point fixed in the tool frame (e.g. the tool tip), seen from the workpiece frame.
    Vec3 toolPointInWorkpiece(const AxisVector& q, const Vec3& pointInToolFrame) const;
    /// Point in the tool frame at distance `length` along the tool direction, plus an offset ([MultiTasking] eq. (15)).
    Vec3 toolPoint(double length, const Vec3& offset = Vec3::Zero()) const {
        return model_.machine().toolDirection * length + offset;
    }

    /// Every moving axis' line in the bed frame at commands q (for Jacobians).
    JointFrames jointFrames(const AxisVector& q) const;

    /// Throws ModelError when a command is outside an axis' travel or not finite.
    void checkTravel(const AxisVector& q) const;

private:
    KinematicsModel model_;
};

}  // namespace cnccomp
