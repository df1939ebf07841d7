#pragma once
// The forward kinematics of one machine (nominal, or with a deviation set), compiled for the post-processor's hot
// loop: the same model as cnccomp::Kinematics (link i = placement · E_location · motion(q) · E_component(q), exact
// rotations), with the constant transforms between two motions folded into one, rotations about a coordinate axis
// built from one sincos, component errors whose coefficients are all zero left out, no allocation per call.
// The tests compare it with cnccomp::Kinematics and toolPoseJacobian.
#include <cmath>
#include <vector>

#include "cnccomp/deviations.hpp"
#include "cnccomp/inverse_kinematics.hpp"

namespace cnccomp::pp {

/// A rigid transform as rotation and translation (frame b in frame a).
struct Frame {
    Mat3 R = Mat3::Identity();
    Vec3 t = Vec3::Zero();
    Vec3 operator*(const Vec3& p) const { return R * p + t; }
};

class CompiledKinematics {
public:
    /// `deviations` nullptr: the nominal machine. The machine must outlive this object.
    CompiledKinematics(const MachineModel& machine, const DeviationSet* deviations);

    const MachineModel& machine() const { return *machine_; }
    /// Tool point at `length` along the tool direction, and the tool axis (spindle → tip), in the workpiece frame,
    /// at model commands q (mm, rad).
    void toolPose(const AxisVector& q, double length, Vec3& tip, Vec3& axis) const;
    Vec3 toolTip(const AxisVector& q, double length) const;
    /// toolPose without the workpiece chain's cache: its operations inverted and applied to the tool point and
    /// direction (about half the arithmetic of building its frame), for commands met once (Newton steps, checks).
    void toolPoseOnce(const AxisVector& q, double length, Vec3& tip, Vec3& axis) const;
    /// The tool axis alone (as toolPoseOnce's, without the tool point's arithmetic).
    Vec3 toolAxisOnce(const AxisVector& q) const;
    /// A direction given in the workpiece frame, in the base (bed) frame at q: baseToWorkpiece(q).R · v.
    Vec3 workpieceToBase(const AxisVector& q, const Vec3& v) const;
    /// d(tip, axis)/dq (6 × n, workpiece frame, rows as cnccomp::toolPoseJacobian); also the pose at q.
    void jacobian(const AxisVector& q, double length, PoseJacobian& J, Vec3& tip, Vec3& axis) const;
    /// The tool point at q and its derivatives by the three axes `axes` (linear axes: constant in them).
    void pointJacobian(const AxisVector& q, double length, const int axes[3], Mat3& J, Vec3& tip) const;
    Frame baseToWorkpiece(const AxisVector& q) const;
    Frame baseToTool(const AxisVector& q) const;

private:
    enum class OpKind : uint8_t { Constant, Linear, Rotary, Component };
    /// cos and sin of a rotary op's angle, from the last exactly computed angle when it is close.
    struct Trig {
        mutable double last = HUGE_VAL, lastC = 1, lastS = 0;    ///< the last exactly computed angle
        mutable double asked = HUGE_VAL, askedC = 1, askedS = 0;  ///< the last angle asked for
        void at(double angle, double& c, double& s) const;
        void compute(double angle, double& c, double& s) const;  ///< from `last` by angle addition, or exactly
    };
    struct Op {
        OpKind kind = OpKind::Constant;
        int axis = -1;
        int unit = -1;  ///< rotary direction is +X / +Y / +Z exactly: 0 / 1 / 2; else −1
        int ui = 1, uj = 2;  ///< with `unit`: the plane it turns, (unit + 1) % 3 and (unit + 2) % 3
        Mat3 R = Mat3::Identity();
        Vec3 t = Vec3::Zero();
        Vec3 dir = Vec3::UnitZ();
        bool modulo = false;
        bool identityR = false;  ///< Constant op without rotation
        Trig trig;               ///< Rotary op
        std::vector<int> components;  ///< deviation definitions of a Component op
    };
    struct JointLine {
        int axis = -1;
        bool rotary = false;
        Vec3 direction, point;
    };
    struct Lines {
        JointLine items[kMaxAxes];
        int count = 0;
    };
    /// A chain without rotary motion or component errors is affine in its axes: R constant, t = t0 + Σ colₖ qₖ
    /// (evaluated without walking its operations).
    struct Affine {
        bool ok = false;
        Mat3 R = Mat3::Identity();
        Vec3 t0 = Vec3::Zero();
        int count = 0;
        int axis[kMaxAxes] = {};
        Vec3 col[kMaxAxes];    ///< base-frame direction of each axis (also its joint line's direction)
        Vec3 start[kMaxAxes];  ///< where each axis' joint line starts with the axes before it at 0
    };
    /// The last two evaluations of a chain, reused while the positions of its own axes are unchanged (consecutive
    /// evaluations often share the rotary positions: the nominal target, the TCP world point, the check).
    struct ChainEntry {
        bool valid = false, hasLines = false;
        double key[kMaxAxes] = {};
        Frame frame;
        Lines lines;
    };
    struct ChainCache {
        ChainEntry entry[2];
        int next = 0;  ///< entry replaced next
    };
    struct ChainOps {
        std::vector<Op> ops;
        std::vector<int> axes;
        Affine affine;
    };
    void compile(const Chain& chain, Side side, ChainOps& c);
    /// v ← Rot(op's direction, θ)ᵀ v, given c = cos θ and s = sin θ.
    static void rotateBack(const Op& op, double c, double s, Vec3& v);
    /// A base-frame point (WithPoint) and direction into the workpiece frame at q, the workpiece chain's operations
    /// inverted one by one (no frame built).
    template <bool WithPoint>
    void intoWorkpiece(const AxisVector& q, Vec3& point, Vec3& direction) const;
    /// The error transform of a Component op at q.
    Pose componentError(const Op& op, const AxisVector& q) const;
    void evaluate(const ChainOps& c, const AxisVector& q, Frame& f, Lines* lines) const;
    /// The evaluation of chain c at q (with its joint lines when `lines`), valid until the next call on `cache`.
    const ChainEntry& cached(const ChainOps& c, ChainCache& cache, const AxisVector& q, bool lines) const;

    const MachineModel* machine_;
    Eigen::VectorXd values_;
    ChainOps workpiece_, tool_;
    mutable ChainCache workpieceCache_, toolCache_;  ///< not thread-safe: one object per thread
};

}  // namespace cnccomp::pp
