#pragma once
// The kinematics engine, the one chain walk of cnccomp: the forward kinematics of one machine (nominal, or with a
// deviation set) compiled once into an immutable model, evaluated with an explicit workspace that the caller owns (the
// split of Pinocchio's Model and Data: Carpentier et al., "The Pinocchio C++ library", SII 2019, §III-A). The model:
// link i = placement · E_location · motion(q) · E_component(q), exact rotations ([MultiTasking] eq. (7), (10)).
//
// KinematicsModel is immutable and may be shared between threads. KinematicsData holds everything an evaluation
// reuses from the previous ones (the last two poses of each chain, the last angles' cosines and sines); give each
// thread its own. A Data follows the model it was last used with: handed to another model it starts empty.
// Two arithmetics:
// - Arithmetic::Fast (`correct`): the constant transforms between two motions folded into one, rotations about a
//   coordinate axis built from one sincos, component errors whose coefficients are all zero left out, affine chains
//   summed, angles near the last one by angle addition, no allocation per call. It agrees with the exact walk
//   (tests/core/test_kinematics_engine.cpp: every sample machine, random deviations and poses, to 1e-12 mm); the last
//   bits may differ.
// - Arithmetic::AsExactModel, the exact model: every link's product from the identity, sin and cos of every angle as
//   Eigen's AngleAxis, toolPose through the inverse of the workpiece pose. cnccomp::Kinematics (kinematics.hpp) is such
//   a model evaluated without a workspace (chainFrame: simulation, identification, the inverse solver, the
//   controllers' apply models); with a workspace (the volumetric map) the frames and toolPose are bit for bit the same,
//   with the savings that change no bit: the last kFrameMemo frames of each chain (keyed by the bit patterns of the
//   chain's own axes; the one found last is looked at first), the inverse of each kept workpiece frame, a chain's walk
//   resumed at its first operation whose axis changed, and the cosines and sines of the last kAngleMemo angles of each
//   rotary operation (a grid's innermost axis, or a rotary axis, takes few distinct values).
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "cnccomp/deviations.hpp"
#include "cnccomp/machine.hpp"
#include "cnccomp/xyz.hpp"

namespace cnccomp {

/// A rigid transform as rotation and translation (frame b in frame a).
struct Frame {
    Mat3 R = Mat3::Identity();
    Vec3 t = Vec3::Zero();
    Vec3 operator*(const Vec3& p) const { return R * p + t; }
};

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

/// d(tip, axis)/dq: 6 × axis count, workpiece frame; rows 0–2 the tool point, rows 3–5 the tool axis.
using PoseJacobian = Eigen::Matrix<double, 6, Eigen::Dynamic, 0, 6, kMaxAxes>;

class KinematicsModel;

/// Angles whose cosine and sine a workspace keeps per rotary operation, and chain frames it keeps per chain
/// (Arithmetic::AsExactModel).
inline constexpr int kAngleMemo = 64;
inline constexpr int kFrameMemo = 64;

/// The workspace of a KinematicsModel's evaluations (see the file comment). Copyable; no allocation per call (an
/// Arithmetic::AsExactModel model's angle tables are allocated once, when the workspace is bound to it).
class KinematicsData {
public:
    KinematicsData() = default;
    explicit KinematicsData(const KinematicsModel& model);

private:
    friend class KinematicsModel;
    /// cos and sin of one rotary operation's angle: the last exactly computed angle (base of the angle addition) and
    /// the last angle asked for.
    struct Trig {
        double last = HUGE_VAL, lastC = 1, lastS = 0;
        double asked = HUGE_VAL, askedC = 1, askedS = 0;
    };
    /// cos and sin of the last angles of one rotary operation, exactly computed (Arithmetic::AsExactModel): a
    /// direct-mapped table keyed by the angle's bit pattern (kEmptyAngle: no entry; it is a NaN, never a command).
    static constexpr uint64_t kEmptyAngle = 0x7ff8dead0000beefULL;
    struct AngleMemo {
        uint64_t key[kAngleMemo];
        double c[kAngleMemo], s[kAngleMemo];
        AngleMemo() {
            for (uint64_t& k : key) k = kEmptyAngle;
        }
    };
    /// One evaluation of a chain, reused while the positions of its own axes are unchanged.
    struct ChainEntry {
        bool valid = false, hasLines = false;
        double key[kMaxAxes] = {};
        Frame frame;
        JointFrames lines;
    };
    /// The last two evaluations of a chain (consecutive evaluations often share the rotary positions: the nominal
    /// target, the TCP world point, the check).
    struct ChainCache {
        ChainEntry entry[2];
        int next = 0;  ///< entry replaced next
    };
    uint64_t model_ = 0;  ///< id of the model the contents belong to (0: none)
    Trig trig_[kMaxAxes];  ///< per rotary operation (KinematicsModel's Op::slot)
    ChainCache workpiece_, tool_;
    /// Per rotary operation, with Arithmetic::AsExactModel only (empty otherwise: no cost to the fast models).
    std::vector<AngleMemo> angles_;
    /// With Arithmetic::AsExactModel: the frames of each chain at its last axis positions (kFrameMemo entries,
    /// direct-mapped by the bit patterns of the chain's own axes; a grid's innermost axis takes few values).
    struct FrameEntry {
        bool valid = false;
        bool hasInverse = false;  ///< `inverse` holds the frame's inverse (computed once, when toolPose first needs it)
        uint64_t key[kMaxAxes] = {};
        Frame frame;
        Pose inverse = Pose::Identity();  ///< the frame as an isometry, inverted as toolPose(Kinematics) inverts it
    };
    struct FrameMemo {
        std::vector<FrameEntry> entries;
        size_t last = 0;  ///< the entry found last (looked at first: a grid's outer axes hold still for many points)
    };
    FrameMemo workpieceFrames_, toolFrames_;
    /// With Arithmetic::AsExactModel: the last walk of one chain, to be resumed. For every operation that depends on
    /// an axis (linear, rotary, component error), the bits of that axis and the frame before the operation; a walk at
    /// new commands starts from the first such operation whose axis changed (the operations before it would compute the
    /// same bits again: a grid varies its last axes fastest).
    struct WalkTrace {
        bool valid = false;
        std::vector<uint64_t> key;  ///< per operation (those that depend on no axis: unused)
        std::vector<Frame> before;  ///< per operation: the frame before it
        Frame last;                 ///< the frame after the last operation
    };
    WalkTrace workpieceWalk_, toolWalk_;
};

class KinematicsModel {
public:
    /// How the model rounds (see the file comment).
    enum class Arithmetic : uint8_t {
        Fast,          ///< constants folded, affine chains summed, angle addition near the last angle
        AsExactModel,  ///< the exact model's operations in their order (cnccomp::Kinematics is this arithmetic)
    };
    /// `deviations` nullptr: the nominal machine; a set of another machine is refused (ModelError, requireMachine).
    /// The machine must outlive this object.
    KinematicsModel(const MachineModel& machine, const DeviationSet* deviations, Arithmetic arithmetic = Arithmetic::Fast);

    const MachineModel& machine() const { return *machine_; }
    Arithmetic arithmetic() const { return exact_ ? Arithmetic::AsExactModel : Arithmetic::Fast; }
    /// A fresh workspace for this model (as KinematicsData(model)).
    KinematicsData createData() const { return KinematicsData(*this); }

    /// Tool point at `length` along the tool direction, and the tool axis (spindle → tip), in the workpiece frame,
    /// at model commands q (mm, rad). With Arithmetic::AsExactModel: toolPose(Kinematics, q, toolPoint(length)) to the
    /// bit (the tool point as Kinematics::toolPoint, the workpiece pose inverted as an isometry).
    void toolPose(KinematicsData& d, const AxisVector& q, double length, Vec3& tip, Vec3& axis) const;
    Vec3 toolTip(KinematicsData& d, const AxisVector& q, double length) const;
    /// toolPose without the workpiece chain's cache: its operations inverted and applied to the tool point and
    /// direction (about half the arithmetic of building its frame), for commands met once (Newton steps, checks).
    void toolPoseOnce(KinematicsData& d, const AxisVector& q, double length, Vec3& tip, Vec3& axis) const;
    /// The tool axis alone (as toolPoseOnce's, without the tool point's arithmetic).
    Vec3 toolAxisOnce(KinematicsData& d, const AxisVector& q) const;
    /// The tool point alone (as toolPoseOnce's to the bit, without the tool axis' arithmetic).
    Vec3 toolTipOnce(KinematicsData& d, const AxisVector& q, double length) const;
    /// The tool point at `length` along the tool direction, and the tool direction, in the base (bed) frame at q.
    void toolInBase(KinematicsData& d, const AxisVector& q, double length, Vec3& tip, Vec3& axis) const;
    /// A point given in the workpiece frame, in the base frame at q: baseToWorkpiece(q) · p, the workpiece chain's
    /// operations applied to it one by one (no frame built).
    Vec3 workpiecePointToBase(KinematicsData& d, const AxisVector& q, const Vec3& p) const;
    /// Gives `d` the cosines and sines of the rotary angles that `from`, a workspace of `other`, holds (the last
    /// angles asked for and the bases of the angle addition), when `other` is a model of the same machine (its rotary
    /// operations numbered alike) and both are Arithmetic::Fast; else nothing changes. The nominal and the erroneous
    /// model of one machine are evaluated at the same angles in turn (a check of a corrected point): the second
    /// evaluation then computes no cosine or sine.
    void takeAngles(KinematicsData& d, const KinematicsModel& other, const KinematicsData& from) const;
    /// d(tip, axis)/dq (6 × n, workpiece frame, rows as cnccomp::toolPoseJacobian); also the pose at q.
    void jacobian(KinematicsData& d, const AxisVector& q, double length, PoseJacobian& J, Vec3& tip, Vec3& axis) const;
    /// The tool point at q and its derivatives by the three axes `axes` (linear axes: constant in them).
    void pointJacobian(KinematicsData& d, const AxisVector& q, double length, const int axes[3], Mat3& J, Vec3& tip) const;
    Frame baseToWorkpiece(KinematicsData& d, const AxisVector& q) const;
    Frame baseToTool(KinematicsData& d, const AxisVector& q) const;

    /// The frame of one chain at q (bMw for Side::Workpiece, bMt for Side::Tool) and, when `joints`, its moving axes'
    /// lines appended there, without a workspace: the exact model's arithmetic (every link's product from the
    /// identity, sin and cos of every angle as Eigen's AngleAxis), nothing cached, safe to call from any thread. With
    /// Arithmetic::AsExactModel this is cnccomp::Kinematics, which calls it; with Arithmetic::Fast it walks the folded
    /// operations (agreeing to round-off).
    Frame chainFrame(Side side, const AxisVector& q, JointFrames* joints = nullptr) const;

private:
    friend class KinematicsData;
    using Trig = KinematicsData::Trig;
    using ChainEntry = KinematicsData::ChainEntry;
    using ChainCache = KinematicsData::ChainCache;
    enum class OpKind : uint8_t { Constant, Linear, Rotary, Component };
    struct Op {
        OpKind kind = OpKind::Constant;
        int axis = -1;
        int slot = -1;  ///< Rotary op: its Trig in KinematicsData
        int unit = -1;  ///< rotary direction is +X / +Y / +Z exactly: 0 / 1 / 2; else −1
        Mat3 R = Mat3::Identity();
        Vec3 t = Vec3::Zero();
        Vec3 dir = Vec3::UnitZ();
        bool modulo = false;
        bool identityR = false;  ///< Constant op without rotation
        std::vector<int> components;  ///< deviation definitions of a Component op
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
        Vec3 toolAxis = Vec3::UnitZ();  ///< R · the machine's tool direction (the tool chain's axis in the base frame)
    };
    struct ChainOps {
        Side side = Side::Tool;
        std::vector<Op> ops;
        std::vector<int> axes;
        Affine affine;
    };
    void compile(const Chain& chain, Side side, ChainOps& c, int& slots);
    /// `d` emptied when it belongs to another model (the test inline: every evaluation makes it).
    void bind(KinematicsData& d) const {
        if (d.model_ != id_) rebind(d);
    }
    void rebind(KinematicsData& d) const;
    /// cos and sin of `angle` for a rotary op: the same angle again from `asked`, an angle near the last exactly
    /// computed one by angle addition, else exactly.
    static void trig(Trig& t, double angle, double& c, double& s);
    /// cos and sin of a rotary op's angle: trig (inlined into the caller), or with Arithmetic::AsExactModel exactTrig.
    void trigOf(KinematicsData& d, const Op& op, double angle, double& c, double& s) const;
    /// std::cos and std::sin (as Eigen's AngleAxis) through the workspace's table of the last angles.
    void exactTrig(KinematicsData& d, const Op& op, double angle, double& c, double& s) const;
    /// v ← Rot(op's direction, θ)ᵀ v, given c = cos θ and s = sin θ (a point or direction of a walk, xyz.hpp).
    static void rotateBack(const Op& op, double c, double s, xyz::Xyz& v);
    /// A base-frame point (WithPoint) and direction into the workpiece frame at q, the workpiece chain's operations
    /// inverted one by one (no frame built).
    template <bool WithPoint, bool WithDirection = true>
    void intoWorkpiece(KinematicsData& d, const AxisVector& q, Vec3& point, Vec3& direction) const;
    /// The error transform of a Component op at q.
    Pose componentError(const Op& op, const AxisVector& q) const;
    /// The walk of chain c's operations with the exact model's arithmetic (Exact; see chainFrame) or the fast one;
    /// `trigOf(op, angle, c, s)` gives cos and sin of a rotary op's angle.
    /// `trace` (Exact only, or nullptr): resumed where the commands of `trace`'s walk first differ from q, and updated.
    template <bool Exact, class TrigOf>
    void walk(const ChainOps& c, const AxisVector& q, Frame& f, JointFrames* lines, TrigOf&& trigOf,
              KinematicsData::WalkTrace* trace = nullptr) const;
    void evaluate(KinematicsData& d, const ChainOps& c, const AxisVector& q, Frame& f, JointFrames* lines) const;
    /// The evaluation of chain c at q (with its joint lines when `lines`), valid until the next call on `cache`.
    const ChainEntry& cached(KinematicsData& d, const ChainOps& c, ChainCache& cache, const AxisVector& q,
                             bool lines) const;
    /// Arithmetic::AsExactModel: the frame of chain c at q from the workspace's frame table `memo`.
    KinematicsData::FrameEntry& memoFrame(KinematicsData& d, const ChainOps& c, KinematicsData::FrameMemo& memo,
                                          const AxisVector& q) const;

    const MachineModel* machine_;
    bool exact_ = false;  ///< Arithmetic::AsExactModel
    int rotarySlots_ = 0;
    uint64_t id_;  ///< distinct for every constructed model (copies share it: same contents)
    Eigen::VectorXd values_;
    ChainOps workpiece_, tool_;
};

}  // namespace cnccomp
