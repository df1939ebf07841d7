#pragma once
// Correction of motion endpoints and paths: axis commands that make the erroneous machine
// (Kinematics(m, d)) put its tool where the nominal machine (Kinematics(m)) would, and the subdivision of
// moves where the straight (or circular) interpolation of corrected commands would leave the nominal path
// by more than a tolerance. Allocation free in the hot path.
#include <vector>

#include <Eigen/Cholesky>

#include "cnccomp/inverse_kinematics.hpp"
#include "postproc/modal.hpp"

namespace cnccomp::pp {

struct CorrectorOptions {
    double toleranceMm = 1e-3;     ///< largest allowed distance of the tool tip from the nominal path
    bool tipOnly = false;          ///< rotary axes keep their commands; only the tool tip is corrected
    double rotaryDamping = 1.0;    ///< mm (weighted residual) per rad of extra rotary motion: keeps rotary
                                   ///< corrections bounded where the tool axis cannot be corrected (singular poses)
    double axisWeight = 100.0;     ///< mm per rad: how much a tool-axis error counts against a tip error
    double solveTolerance = 1e-7;  ///< mm: Newton stops when its step is below this (and 1e-9 rad); the
                                   ///< residual left is far smaller (quadratic / fast linear convergence)
    int maxIterations = 30;
    int maxDepth = 14;             ///< subdivision levels per move
    int maxPieces = 16384;         ///< pieces per move
};

struct SolveResult {
    double tipError = 0.0;   ///< mm, remaining tip distance
    double axisError = 0.0;  ///< rad, remaining tool-axis angle
    int iterations = 0;
    bool converged = false;
};

/// Nominal path of one move in machine coordinates, t ∈ [0, 1]: straight in every axis (G0/G1), or a circle
/// (spiral when start and end radius differ, as RS274NGC interpolates) in the plane axes with the other
/// axes straight (G2/G3, helices).
struct MovePath {
    bool circular = false;
    AxisVector start, end;
    int axis0 = -1, axis1 = -1;
    double c0 = 0, c1 = 0, r0 = 0, r1 = 0, theta0 = 0, sweep = 0;

    static MovePath line(const AxisVector& start, const AxisVector& end);
    static MovePath arc(const AxisVector& start, const AxisVector& end, const ArcGeometry& g);
    void at(double t, AxisVector& q) const;
};

struct Piece {
    double t = 1.0;  ///< parameter on the nominal path the piece ends at
    AxisVector q;    ///< corrected commands at its end
};

struct SplitStats {
    double maxDeviation = 0.0;  ///< mm: largest tip deviation left at a checked midpoint
    int solves = 0;
    bool limited = false;       ///< depth or piece limit reached with the tolerance not met
};

struct ArcFit {
    bool ok = false;
    double c0 = 0, c1 = 0;      ///< centre of the corrected arc, machine coordinates (plane axes)
    double sweep = 0;           ///< signed sweep of the corrected arc
    double maxDeviation = 0.0;  ///< mm, at the sampled points
};

class Corrector {
public:
    Corrector(const MachineModel& machine, const DeviationSet& deviations, const CorrectorOptions& options = {});

    /// True when every deviation is zero: corrected commands are the commands, nothing is solved.
    bool identity() const { return identity_; }
    const CorrectorOptions& options() const { return options_; }
    const Kinematics& nominal() const { return nominal_; }
    const Kinematics& actual() const { return actual_; }

    /// Commands `q` near `start` at which the erroneous machine puts the point at `toolLength` along the tool,
    /// and the tool axis, where the nominal machine puts them at `qNom`. Regularised Gauss–Newton on the exact
    /// model: the tip is matched exactly (linear axes are free), the tool axis in the least-squares sense with
    /// rotary corrections damped by options().rotaryDamping (exact away from singular poses).
    SolveResult solve(const AxisVector& qNom, double toolLength, const AxisVector& start, AxisVector& q) const;

    /// Distance (mm) between the nominal tool tip at `qNom` and the actual tool tip at `q`.
    double tipDeviation(const AxisVector& qNom, const AxisVector& q, double toolLength) const;

    /// Appends pieces (ending at t = 1 with `qEnd`) so that straight interpolation between consecutive corrected
    /// commands, starting from `outStart`, stays within the tolerance of `path` at every checked midpoint.
    /// `subdivide` false: one piece, deviation still measured at the midpoint.
    void split(const MovePath& path, const AxisVector& outStart, const AxisVector& qEnd, double toolLength,
               bool subdivide, std::vector<Piece>& pieces, SplitStats& stats) const;

    /// Corrected arc from `outStart` to `qEnd` that stays a circle in the same plane: its centre is the nominal
    /// centre corrected, moved onto the bisector of the corrected end points; ok when every sampled point is
    /// within the tolerance of the nominal arc.
    ArcFit fitArc(const MovePath& path, const AxisVector& outStart, const AxisVector& qEnd, double toolLength,
                  bool closed) const;

    /// Arc → straight pieces: chords short enough for the tolerance, each checked and split like a line.
    void splitArc(const MovePath& path, const AxisVector& outStart, const AxisVector& qEnd, double toolLength,
                  std::vector<Piece>& pieces, SplitStats& stats) const;

private:
    /// Jacobian of the erroneous machine and its factorised normal matrix, kept from one solve to the next
    /// while the commands stay close (chord Newton): consecutive program points differ little.
    struct JacobianCache {
        bool valid = false;
        double toolLength = 0;
        AxisVector q;
        PoseJacobian J;
        Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxAxes, kMaxAxes> A, Ainv;  ///< normal matrix, inverse
        Eigen::Matrix<double, Eigen::Dynamic, 6, 0, kMaxAxes, 6> gain;  ///< Ainv · Jᵀ (n × 6)
    };
    void refreshJacobian(const AxisVector& q, double toolLength, const Vec3& tip) const;
    bool cacheUsable(const AxisVector& q, double toolLength) const;
    void splitRecursive(const MovePath& path, double t0, const AxisVector& q0, double t1, const AxisVector& q1,
                        double toolLength, int depth, std::vector<Piece>& pieces, SplitStats& stats) const;
    const MachineModel& machine_;
    Kinematics nominal_, actual_;
    CorrectorOptions options_;
    bool identity_ = false;
    bool affine_ = false;  ///< no component errors: with rotary axes fixed, the error is affine in the linear axes
    AxisMask rotary_ = 0;
    mutable JacobianCache cache_;  ///< not thread-safe: one Corrector per program being corrected
};

}  // namespace cnccomp::pp
