#pragma once
// A controller's own kinematic model, rebuilt from the files it was given, and the tool-centre-point (TCP)
// transformation that solves it. Shared by the kinematic-parameter backends (Siemens kinematic chain,
// Heidenhain kinematics table, Fanuc 5-axis TCP parameters).
//
// A controller file describes each chain from the bed outwards as constant transforms (offsets, rotations)
// and axis motions, plus position-dependent tables. ControllerModel turns that into a MachineModel of its own
// (same axes, same order, travel and modulo taken from the real machine) with the tables as component errors,
// so the exact kinematics and the Newton inverse of the foundation (Kinematics, solveToolPose) model the
// controller: the program's nominal tool pose is reached on the controller's corrected model.
#include <memory>
#include <string>
#include <vector>

#include "cnccomp/inverse_kinematics.hpp"
#include "cnccomp/kinematics.hpp"

namespace cnccomp::controllers::common {

/// Tool length (mm from the tool reference point) the apply models assume for the TCP. With five axes the
/// full pose (tip and axis) is matched, so the tip is right for any tool length; with four axes the tip is
/// matched at this length only.
inline constexpr double kControllerToolLength = 100.0;

/// Controlled axes in the order a controller numbers them: X Y Z U V W A B C, then other names in the
/// machine's order. Returns machine axis indices (AxisVector positions).
std::vector<int> controllerAxisOrder(const MachineModel& m);
/// 1-based controller number (AX1, A1, ...) of a machine axis index.
int controllerAxisNumber(const MachineModel& m, int machineAxis);
/// Machine axis index of a 1-based controller number, or -1.
int machineAxisOfNumber(const MachineModel& m, int number);

/// One element of a chain read from the bed outwards: a constant transform or an axis motion.
struct ChainElement {
    enum class Type { Constant, Axis };
    Type type = Type::Constant;
    Pose pose = Pose::Identity();   ///< Constant: the transform
    int axis = -1;                  ///< Axis: machine axis index
    Vec3 direction = Vec3::UnitZ(); ///< Axis: unit direction of motion / rotation in the current frame
    static ChainElement constant(const Pose& p) { return {Type::Constant, p, -1, Vec3::UnitZ()}; }
    static ChainElement motion(int axis, const Vec3& direction) {
        return {Type::Axis, Pose::Identity(), axis, direction};
    }
};

/// A position-dependent error of one axis, linearly interpolated (ends held; a modulo axis wraps), applied
/// after the axis motion like a component error (component 0..5 = x y z a b c of the moving frame).
struct ComponentTable {
    int axis = -1;
    int component = 0;
    std::vector<double> nodes;   ///< mm or rad, strictly increasing; on a modulo axis spanning less than 360°
    std::vector<double> values;  ///< mm or rad
};

/// The controller's corrected kinematic model, in the controller's own axis coordinates (machine coordinates:
/// command − Link::machineZero; the links' travel is shifted to match). Throws ModelError when the chains do not hold
/// exactly the machine's axes in the machine's order (workpiece chain first, each chain from the bed outwards).
class ControllerModel {
public:
    ControllerModel(const MachineModel& machine, const std::vector<ChainElement>& workpiece,
                    const std::vector<ChainElement>& tool, const std::vector<ComponentTable>& tables = {});
    const MachineModel& model() const { return *model_; }
    const Kinematics& kinematics() const { return *kinematics_; }

private:
    std::unique_ptr<MachineModel> model_;
    std::unique_ptr<DeviationSet> set_;
    std::unique_ptr<Kinematics> kinematics_;
};

/// The TCP of a controller: programmed commands (meant for the nominal machine, in the description's frame) →
/// nominal tool pose → the controller's machine coordinates at which its model (ControllerModel, controller
/// coordinates) reaches that pose (Newton, solveToolPose) → back to the description's frame
/// (MachineModel::fromController). The tool point is the active tool's tip: a TCP control computes with the length of
/// the active tool's offset — Sinumerik: "an activated tool length compensation is included in the transformation"
/// (840D sl Function Manual, transformations, "Selection and deselection"); HEIDENHAIN M128: "the position of the tool
/// tip to the workpiece remains the same", "the tool length must refer to the spherical center of the tool tip" (TNC 620
/// User's Manual DIN/ISO 5/2013, 11.4, p.340; iTNC 530 User's Manual, M128, p.524); Fanuc G43.4 with the tool length
/// offset H (A-79348E) — so where the tool axis cannot be matched (four axes, or a singular orientation) the tip of
/// that tool is still met. The machine must outlive the transform.
class TcpTransform {
public:
    TcpTransform(const MachineModel& machine, std::unique_ptr<const ControllerModel> controller,
                 double toolLength = kControllerToolLength);
    /// With the default tool length (constructor).
    AxisVector solve(const AxisVector& programmed) const;
    /// With the active tool's length (mm along the machine's tool direction from the tool reference point).
    AxisVector solve(const AxisVector& programmed, double toolLength) const;
    const ControllerModel& controller() const { return *controller_; }
    double toolLength() const { return toolLength_; }

private:
    Kinematics nominal_;
    std::unique_ptr<const ControllerModel> controller_;
    double toolLength_;
};

/// The six location-error components (x y z a b c) a deviation set puts on one link (mm, rad).
Vec6 linkLocationError(const MachineModel& m, const Eigen::VectorXd& values, Side side, int link);

/// Rotation matrix → angles (a, b, c) with R = Rx(a)·Ry(b)·Rz(c) (exact for |b| < 90°).
Vec3 xyzAngles(const Mat3& r);
Mat3 fromXyzAngles(const Vec3& abc);

/// Fixed-point text without a negative zero ("-0.000" → "0.000").
std::string fixed(double v, int decimals);

}  // namespace cnccomp::controllers::common
