#pragma once
// Tilting-head errors from head patterns (J. Fan, C. Wu, Z. Li, "A novel geometric error identification methodology
// for the tilting head of five-axis machine tools based on double ball bar", [FanWuLi]): geometric errors of a tilting head B from a double ball bar in Y, X and Z patterns,
// each with two tool lengths L1 < L2. The spindle turns about Ball 1 while X/Y/Z keep Ball 1 still; Ball 2 sits at
// its nominal position O and Δd is the length change from the nominal bar length (absolute bar, section 3.1).
// The patterns are the [MultiTasking] runs B-Y, B-X, B-Z (RB = L, LB = d) simulated with Ball 2 at O.
//
// Formulas (first order, as derived in the paper, with the signs of this library's model):
//   Y: L·Q_j + δy(B_j) = Δd_y (4)-(5);  Q_j = (Δd_y2 − Δd_y1)/(L2 − L1), δy = (L2 Δd_y1 − L1 Δd_y2)/(L2 − L1)  (7)
//      εBz = Q(0°), εxB = (Q(270°) − Q(90°))/2, εx(B) = Q − εBz cos B + εxB sin B                          (9)
//   X: −L cos B εy(B) + P_j = Δd_x (13)-(14); εy = −(Δd_x2 − Δd_x1)/((L2 − L1) cos B), P = (L2Δd_x1 − L1Δd_x2)/(L2 − L1)  (16)
//      (eq. (16) as printed drops the minus sign that follows from (15)); where |cos B| < ½ the same difference is
//      taken in the Z pattern instead: εy = (Δd_z2 − Δd_z1)/((L2 − L1) sin B) (from (20) with two tool lengths).
//   Z: R_j = Δd_z1 − L1 sin B εy;  δz = cos B R + sin B P,  δx = cos B P − sin B R                            (20)-(21)
// Gauge of the paper: εx(0) = 0 and εx(90°) = εx(270°) (270° ≡ −90° on a ±120° head).
// Names in the machine: εxB = EC0B (B axis about Z), εBz = EA0B (B axis about X), δx(B)…εy(B) = EXB EYB EZB EAB EBB
// (component errors of B, placed after its rotation, i.e. in the rotating head frame as the paper's {s_j^e}).
#include <string>
#include <vector>

#include "cnccomp/ballbar.hpp"
#include "cnccomp/deviations.hpp"
#include "cnccomp/identification/lsq.hpp"

namespace cnccomp::identification {

/// ΔL of a ball-bar run with Ball 2 at its nominal position (where the nominal machine puts the T-side ball at the
/// setup commands) plus the run's work-ball offset: an absolutely calibrated bar on a located socket.
BallbarTrace simulateAbsoluteRun(const Kinematics& k, const BallbarRun& run);

/// Per-angle result of the formulas, internal units (mm, rad).
struct TiltingHeadAngle {
    double angleDeg = 0;
    double dx = 0, dy = 0, dz = 0, ex = 0, ey = 0;  ///< δx(B) δy(B) δz(B) εx(B) εy(B)
    double Q = 0, P = 0, R = 0;                     ///< the paper's intermediate sums
    bool eyFromZ = false;                           ///< εy taken from the Z pattern (|cos B| < ½)
};

struct TiltingHeadResult {
    std::string headAxis = "B";
    double L1 = 0, L2 = 0;      ///< tool lengths, mm
    double exB = 0, eBz = 0;    ///< εxB, εBz, rad
    std::vector<TiltingHeadAngle> angles;  ///< common sample angles of the six runs, ascending
};

/// Applies eq. (7), (9), (16), (21) to the B-Y, B-X and B-Z runs of a plan (two tool lengths each; other runs are
/// ignored) and their absolute traces. Throws ModelError naming what is missing (a pattern, a second tool length,
/// the angles 0° and ±90°).
TiltingHeadResult tiltingHeadFormulas(const std::vector<BallbarRun>& runs, const std::vector<BallbarTrace>& traces);

/// Deviation set from the per-angle results: location EC0B (εxB) and EA0B (εBz), and the component errors
/// E[X|Y|Z|A|B]<head> as tables, their node values interpolated linearly between the measured angles.
/// Throws ModelError when the machine lacks a needed deviation or a table node lies outside the measured angles.
DeviationSet tiltingHeadDeviations(const MachineModel& machine, const TiltingHeadResult& r);

/// Least-squares equivalent: the component errors of the head axis (tables) identified by the general engine from
/// the same absolute ΔL samples, then split into εxB, εBz and εx(B) with the paper's gauge (eq. (9)) by an exact
/// change of frame. Unknowns: E[X|Y|Z|A|B]<head> (εz(B) is invisible to a ball on the spindle axis).
struct TiltingHeadLsq {
    IdentificationResult engine;  ///< the engine's solution before the gauge split (εx carries Q)
    DeviationSet deviations;      ///< after the gauge split (EC0B, EA0B and the five tables present)
};
TiltingHeadLsq tiltingHeadLeastSquares(const MachineModel& machine, const std::vector<BallbarRun>& runs,
                                       const std::vector<BallbarTrace>& traces, const IdentifyOptions& options = {});

}  // namespace cnccomp::identification
