#pragma once
// Correction of motion endpoints and paths: positions that make the erroneous machine (the deviation set) put its
// tool where the nominal machine would, and the subdivision of moves where the interpolation of corrected positions
// would leave the nominal path by more than a tolerance. Allocation free in the hot path.
//
// Positions are "program space": what the controller interpolates between block endpoints, in its machine units
// (mm, rad) after work offsets — its machine coordinates (joint mode), or in TCP mode the world point of the tool and
// the rotary angles / tool vector (postproc/tcp_model.hpp). Machine coordinates are the controller's: the model's
// commands are machine coordinates + machine-zero (MachineModel::fromController), converted here where they meet it.
#include <cmath>
#include <vector>

#include "cnccomp/kinematics_engine.hpp"
#include "cnccomp/pose_solver.hpp"
#include "postproc/midpoint_bound.hpp"
#include "postproc/modal.hpp"
#include "postproc/tcp_model.hpp"

namespace cnccomp::postproc {

struct CorrectorOptions {
    double toleranceMm = 1e-3;     ///< largest allowed distance of the tool tip from the nominal path
    bool tipOnly = false;          ///< rotary axes keep their commands; only the tool tip is corrected
    double rotaryDamping = 5.0;    ///< mm (weighted residual) per rad of rotary correction, in the ill-conditioned
                                   ///< directions only (see singularSine): near a singular pose (tool axis along a
                                   ///< rotary axis) a rotary axis corrects at most about axisWeight / (2 · rotaryDamping)
                                   ///< = 10 times the tool-axis error it removes instead of swinging
    double continuity = 20.0;      ///< mm per rad of change of a damped rotary correction from the previous end point:
                                   ///< keeps the solution on the branch of the previous block (see Corrector::solve)
    double singularSine = 0.1;     ///< damping and continuity act in the directions where a singular value of the tool
                                   ///< axis' derivatives by the rotary axes (rad/rad) is below this, weighted
                                   ///< (1 − σ/singularSine)²; at or above it (tool axis ≥ 5.7° from every rotary axis
                                   ///< on a 5-axis machine) the solution is exact
    double axisWeight = 100.0;     ///< mm per rad: how much a tool-axis error counts against a tip error
    double solveTolerance = 1e-6;  ///< mm: Newton stops when its step is below this (rotary: below this / 100 mm in
                                   ///< rad); the step is applied, the residual left is a small part of it
    int maxIterations = 30;
    int maxDepth = 14;             ///< subdivision levels per move
    int maxPieces = 16384;         ///< pieces per move
    bool boundChecks = true;       ///< leave out a midpoint check whose result the midpoint bound settles (it changes
                                   ///< nothing written or reported: postproc/midpoint_bound.hpp)
};

/// The nominal machine's tool point at `length` along the tool and its tool axis (spindle → tip), workpiece frame.
struct NominalPose {
    bool known = false;
    double length = 0;
    Vec3 tip = Vec3::Zero(), axis = Vec3(0, 0, -1);
};

struct SolveResult {
    double tipError = 0.0;   ///< mm, remaining tip distance
    double axisError = 0.0;  ///< rad, remaining tool-axis angle
    int iterations = 0;
    bool converged = false;
};

/// What a move's program positions are, and which tool point is matched.
struct MoveSpace {
    ProgramMode mode = ProgramMode::Joints;
    double controlLength = 0.0;  ///< mm, TCP: the controller's tool length (the programmed point is there)
    double toolLength = 0.0;     ///< mm: the tool point whose position is corrected exactly (and the tool axis)
};

/// A position in program space: the axis vector, and in vector mode the tool vector (world, spindle → tip).
struct ProgramPoint {
    AxisVector p;
    Vec3 v = Vec3(0, 0, -1);
};

/// Nominal path of one move in program space, t ∈ [0, 1]: straight in every coordinate (G0/G1), or a circle (spiral
/// when start and end radius differ, as RS274NGC interpolates) in the plane coordinates with the others straight
/// (G2/G3, helices). In vector mode the tool vector turns in the plane of its end vectors at a constant rate [G].
struct MovePath {
    bool circular = false, vector = false;
    AxisVector start, end;
    Vec3 v0 = Vec3(0, 0, -1), v1 = Vec3(0, 0, -1);
    int axis0 = -1, axis1 = -1;
    double c0 = 0, c1 = 0, r0 = 0, r1 = 0, theta0 = 0, sweep = 0;

    static MovePath line(const AxisVector& start, const AxisVector& end);
    static MovePath arc(const AxisVector& start, const AxisVector& end, const ArcGeometry& g);
    void at(double t, ProgramPoint& q) const;
};

/// Tool vector at fraction t between unit vectors a and b, turning in their plane at a constant rate.
Vec3 slerpVector(const Vec3& a, const Vec3& b, double t);

struct Piece {
    double t = 1.0;  ///< parameter on the nominal path the piece ends at
    ProgramPoint q;  ///< corrected program position at its end
};

struct SplitStats {
    double maxDeviation = 0.0;  ///< mm: largest tip deviation left at a checked midpoint
    int solves = 0;
    bool limited = false;       ///< depth or piece limit reached with the tolerance not met
    bool bounded = false;       ///< the midpoint check was settled by PathContext::midpointBound (not evaluated)
};

struct ArcFit {
    bool ok = false;
    double c0 = 0, c1 = 0;      ///< centre of the corrected arc, program space (plane coordinates)
    double sweep = 0;           ///< signed sweep of the corrected arc
    double maxDeviation = 0.0;  ///< mm, at the sampled points
};

/// Everything a path check needs about one move: its space, its corrected start (program space) and the tip
/// offset of that start from the nominal path's start (non-zero after a block passed through uncorrected: splitting
/// cannot remove it, so it is blended out linearly along the move and not counted as deviation).
struct PathContext {
    MoveSpace space;
    ProgramPoint outStart;
    Vec3 startOffset = Vec3::Zero();
    double tolerance = 1e-3;
    AxisVector guess;  ///< machine coordinates near the move (start of the inverse TCP kinematics in vector mode)
    /// mm: a proven bound of the deviation at the move's midpoint (MidpointBound; HUGE_VAL: none), and the largest
    /// deviation already measured: a bound below both and below the tolerance settles the first midpoint check.
    double midpointBound = HUGE_VAL;
    double largestMeasured = 0.0;
};

class Corrector {
public:
    Corrector(const MachineModel& machine, const DeviationSet& deviations, const CorrectorOptions& options = {});

    /// True when every deviation is zero: corrected positions are the positions, nothing is solved.
    bool identity() const { return identity_; }
    const CorrectorOptions& options() const { return options_; }
    const KinematicsModel& nominal() const { return nominal_; }
    const KinematicsModel& actual() const { return actual_; }
    const TcpModel& tcp() const { return tcp_; }
    /// The midpoint bound of this machine and deviation set (usable() false outside its class).
    const MidpointBound& midpointBound() const { return bound_; }

    /// Machine coordinates of a program position (nominal controller). false when the TCP inverse fails. `pose`
    /// (optional): the nominal tool point and axis there, when the inverse gives them on the way (TCP angles mode).
    bool toJoints(const MoveSpace& s, const ProgramPoint& p, const AxisVector& guess, AxisVector& c,
                  NominalPose* pose = nullptr);
    /// Program position of machine coordinates c.
    void toProgram(const MoveSpace& s, const AxisVector& c, ProgramPoint& p);

    /// Machine coordinates `c` near `start` at which the erroneous machine puts the point at `toolLength` along the
    /// tool, and the tool axis, where the nominal machine puts them at `cNom`. Gauss–Newton on the exact model: the tip
    /// is matched exactly (linear axes are free), the tool axis exactly where the rotary axes can turn it (least
    /// squares where they cannot, e.g. a four-axis machine). Only in ill-conditioned directions — where a singular value
    /// σ of the tool axis' derivatives by the rotary axes is below options().singularSine, i.e. near a singular pose
    /// (tool axis along a rotary axis) — the rotary corrections (c − cNom) are pulled, with weight (1 − σ/σ0)², towards 0
    /// by options().rotaryDamping and, given `neighbourDelta` (the rotary corrections next to this point: at the
    /// previous end point, or the interpolation of a move's corrected ends), towards it by options().continuity: there
    /// the rotary axes stay on the branch of their neighbours and of the programmed value instead of swinging.
    /// `tipShift` moves the target tip (a point of a path whose start offset is blended out).
    /// `target` (optional): the nominal pose at cNom as toJoints gave it (else it is evaluated).
    SolveResult solve(const AxisVector& cNom, double toolLength, const AxisVector& start, AxisVector& c,
                      const AxisVector* neighbourDelta = nullptr, const Vec3& tipShift = Vec3::Zero(),
                      const NominalPose* target = nullptr);

    /// Start for solve() at cNom from the solution at the previous end point (nominal cNomPrev, correction deltaPrev =
    /// its c − cNom): cNom + deltaPrev + S (cNom − cNomPrev), S = ∂(c − cNom)/∂cNom = (JᵀJ + D)⁻¹ Jᵀ (Jnom − J) from the
    /// kept Jacobian J of the erroneous machine and the nominal one at the same commands (first order in the change
    /// of the correction along the program; S is of the deviations' size, so its staleness over the kept Jacobian's
    /// range costs little). Only a start: solve() converges from it as from any other; without a kept Jacobian near
    /// cNom it is cNom + deltaPrev.
    void predictStart(const AxisVector& cNom, const AxisVector& cNomPrev, const AxisVector& deltaPrev, double toolLength,
                      AxisVector& start);

    /// Tip (at `toolLength`) of the nominal machine at cNom minus that of the erroneous machine at c.
    Vec3 tipError(const AxisVector& cNom, const AxisVector& c, double toolLength);
    double tipDeviation(const AxisVector& cNom, const AxisVector& c, double toolLength) {
        return tipError(cNom, c, toolLength).norm();
    }
    /// Tip of the erroneous machine at c.
    Vec3 actualTip(const AxisVector& c, double toolLength);
    Vec3 nominalTip(const AxisVector& c, double toolLength);
    /// Tip (at s.toolLength) of the nominal machine at program position p, in the workpiece frame.
    Vec3 nominalTipOf(const MoveSpace& s, const ProgramPoint& p);

    /// Corrected program position for the nominal one: joints `cNom` (out), solved joints `c` (start `start`,
    /// reference rotary positions `reference`), the program position `out`.
    SolveResult correct(const MoveSpace& s, const ProgramPoint& nominal, const AxisVector& guess, const AxisVector& start,
                        const AxisVector* neighbourDelta, AxisVector& cNom, AxisVector& c, ProgramPoint& out,
                        const Vec3& tipShift = Vec3::Zero());

    /// Appends pieces (ending at t = 1 with `end`) so that the controller's interpolation between consecutive
    /// corrected positions, starting from ctx.outStart, stays within ctx.tolerance of `path` at every checked
    /// midpoint. `subdivide` false: one piece, deviation still measured at the midpoint.
    void split(const MovePath& path, const PathContext& ctx, const ProgramPoint& end, bool subdivide,
               std::vector<Piece>& pieces, SplitStats& stats);

    /// Corrected arc from ctx.outStart to `end` that stays a circle in the same plane: its centre is the nominal
    /// centre corrected, moved onto the bisector of the corrected end points; ok when every sampled point is within
    /// the tolerance of the nominal arc.
    ArcFit fitArc(const MovePath& path, const PathContext& ctx, const ProgramPoint& end, bool closed);

    /// Arc → straight pieces: chords short enough for the tolerance, each checked and split like a line.
    void splitArc(const MovePath& path, const PathContext& ctx, const ProgramPoint& end, std::vector<Piece>& pieces,
                  SplitStats& stats);

    /// Tip deviation of the corrected interpolation at program point `corrected` from the nominal path point `nominal`
    /// at parameter t (with the context's start offset blended out).
    double deviationAt(const PathContext& ctx, const ProgramPoint& nominal, const ProgramPoint& corrected, double t);

private:
    /// Jacobian of the erroneous machine and its factorised normal matrix, kept from one solve to the next while the
    /// commands stay close (chord Newton): consecutive program points differ little.
    struct JacobianCache {
        bool valid = false, factored = false;
        double toolLength = 0;
        AxisVector q;
        PoseJacobian J;                          ///< axis rows weighted by axisWeight
        SmallMatrix JtJ;                         ///< JᵀJ
        AxisMask free = 0;                       ///< of the factorisation
        SmallMatrix D;                           ///< damping of the factorisation (read only when `damped`)
        bool damped = false;                     ///< D is not all zero
        DampedNormalFactor normal;               ///< (JᵀJ + D)⁻¹ and its gain (JᵀJ + D)⁻¹ Jᵀ (pose_solver.hpp)
        bool slopeValid = false;                 ///< `slope` belongs to this Jacobian and factorisation
        bool slopeKnown = false;                 ///< `slope` was computed (perhaps at an earlier Jacobian)
        double slopeLength = 0;                  ///< tool length of `slope`
        SmallMatrix slope;                       ///< ∂(c − cNom)/∂cNom (see predictStart)
        AxisMask sigmaFree = ~0u;                ///< free axes `sigma` was computed for (~0: not computed)
        double sigma = 0;                        ///< smallest singular value of the tool axis' derivatives by the free
                                                 ///< rotary axes at sigmaQ (J's, or the nominal one of dampingFor)
        AxisVector sigmaQ;                       ///< model commands `sigma` belongs to
    };
    /// Rotary damping of one solve: D (n × n, non-zero in the rotary rows and columns of ill-conditioned directions).
    struct Damping {
        bool any = false;
        SmallMatrix D;  ///< read only when `any` (left unset otherwise)
    };
    /// Newton–Raphson (chord method) from `start`; `cache` must be usable there (cacheUsable: solve() sees to it).
    SolveResult solveOn(const KinematicsModel& k, KinematicsData& kd, JacobianCache& cache, const Vec3& targetTip, const Vec3& targetAxis,
                        double toolLength, const AxisVector& start, const AxisVector& reference, const Damping& damping,
                        AxisMask free, AxisVector& c);
    void refreshJacobian(const KinematicsModel& k, KinematicsData& kd, JacobianCache& cache, const AxisVector& q,
                         double toolLength) const;
    bool cacheUsable(const JacobianCache& cache, const AxisVector& q, double toolLength) const;
    void factor(JacobianCache& cache, const Damping& damping, AxisMask free) const;
    bool factorUsable(const JacobianCache& cache, const Damping& damping, AxisMask free) const;
    /// The damping of a solve at target cNom, and the rotary reference it pulls towards (cNom + the neighbour's share).
    void dampingFor(const AxisVector& cNom, double toolLength, AxisMask free, const AxisVector* neighbourDelta,
                    Damping& damping, AxisVector& reference);
    void splitRecursive(const MovePath& path, const PathContext& ctx, double t0, const ProgramPoint& q0, double t1,
                        const ProgramPoint& q1, int depth, std::vector<Piece>& pieces, SplitStats& stats);
    /// Corrected program position of the nominal path at t, started near `near` (program space).
    void correctedAt(const MovePath& path, const PathContext& ctx, double t, const ProgramPoint& near,
                     ProgramPoint& out, SplitStats& stats);

    const MachineModel& machine_;
    KinematicsModel nominal_, actual_;
    KinematicsData nominalData_, actualData_;  ///< the workspaces of nominal_ (shared with tcp_) and actual_
    TcpModel tcp_;
    CorrectorOptions options_;
    MidpointBound bound_;
    AxisVector zero_;      ///< model commands of the controller's machine zero (machine-zero per axis)
    bool zeroIsZero_ = true;  ///< zero_ is 0 on every axis: model commands are the machine coordinates
    /// Model commands of machine coordinates c: c + zero_ (in `scratch`), or c itself when zero_ is 0.
    const AxisVector& model(const AxisVector& c, AxisVector& scratch) const;
    bool identity_ = false;
    bool affine_ = false;  ///< no component errors: with rotary axes fixed, the error is affine in the linear axes
    AxisMask rotary_ = 0;
    AxisConditioning conditioning_;  ///< scratch of dampingFor
    JacobianCache cache_;  ///< kept from one solve to the next (with the workspaces: one Corrector per thread)
    bool lastDamped_ = false;  ///< the last solve was damped (near a singular pose)
};

}  // namespace cnccomp::postproc
