#pragma once
// Exact forward kinematics of a machine with a deviation set (full rotation matrices, no small-angle
// truncation). [MultiTasking]: the tool chain reproduces T = E_Z M_YZ E_Y M_XY E_X M_XB E_B M_BT T_T (eq. (7)),
// the workpiece chain W = M_CZ E_C W_C (eq. (10)).
#include <array>
#include <vector>

#include "cnccomp/deviations.hpp"
#include "cnccomp/machine.hpp"

namespace cnccomp {

/// A moving axis at given commands, in the bed frame: its direction and a point on its line.
struct JointFrame {
    Side side = Side::Tool;
    int axis = -1;
    bool rotary = false;
    Vec3 direction = Vec3::UnitZ();
    Vec3 point = Vec3::Zero();
};

/// Fixed-capacity list of joint frames (no allocation).
struct JointFrames {
    std::array<JointFrame, kMaxAxes> items;
    int count = 0;
    const JointFrame* begin() const { return items.data(); }
    const JointFrame* end() const { return items.data() + count; }
};

/// A machine with its deviations folded into per-link constant transforms. Cheap to evaluate:
/// no allocation per call, safe to share between threads.
class Kinematics {
public:
    /// Nominal machine (all deviations zero).
    explicit Kinematics(const MachineModel& machine);
    /// Erroneous machine.
    Kinematics(const MachineModel& machine, const DeviationSet& deviations);

    const MachineModel& machine() const { return *machine_; }

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
        return machine_->toolDirection * length + offset;
    }

    /// Every moving axis' line in the bed frame at commands q (for Jacobians).
    JointFrames jointFrames(const AxisVector& q) const;

    /// Throws ModelError when a command is outside an axis' travel or not finite.
    void checkTravel(const AxisVector& q) const;

private:
    struct LinkData {
        Pose placed;             ///< placement · E_location
        Vec3 direction;
        AxisKind kind;
        int axis;                ///< index into AxisVector, -1 fixed
        bool modulo;
        std::vector<int> components;  ///< indices of component deviations on this link
    };
    Pose chainPose(const std::vector<LinkData>& links, const AxisVector& q, Side side = Side::Tool,
                   JointFrames* joints = nullptr) const;
    void build(const DeviationSet* deviations);

    const MachineModel* machine_;
    std::vector<LinkData> workpiece_, tool_;
    Eigen::VectorXd values_;  ///< deviation values (for component errors)
};

}  // namespace cnccomp
