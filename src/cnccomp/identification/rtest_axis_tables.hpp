#pragma once
// Per-angle R-test tables ("A simple modeling method to identify the kinematic errors of machine tool rotary table",
// Zhejiang University, [RotaryTableModel]): the six kinematic errors of each rotary axis of a cradle (A tilting table carrying a
// C rotary table) as functions of its angle — three linear shifts δ(θ) and three angular errors ξ(θ) of the axis'
// rotating frame — and the small-angle model of the workpiece point, eq. (1)–(7):
//   ᶜW = ᶜδ(γ) + R(ᶜξ(γ))·W_N (1),   ᴬW = ᴬδ(α) + R(ᴬξ(α))·(Rot_C(γ)·ᶜW) (4),   W_F = Rot_A(α)·ᴬW,
// with R(ξ) = I + [ξ]× (3), (5) and Rot_A, Rot_C the nominal rotations (6), (7). (As printed, (6) is the rotation
// about X and (7) about Z, labelled with the other axis' angle, and (2)–(3) drop δz and ξz; the six-error model of the
// text is used here.) In the machine these are the component errors E[X|Y|Z|A|B|C]<axis>, placed after the axis'
// rotation, as tables over the angle.
//
// Measurement: R-test runs in which one rotary axis turns (the other held), with the ball at ≥ 3 non-collinear
// positions on the table. At each angle the displacements of the balls, rotated into the axis frame, satisfy
// Δ_k = δ + ξ × p_k (small-angle form of (1)/(4)), solved by linear least squares for (δ, ξ).
// Gauge: a constant transform between the A and C frames cannot be seen by any measurement; the convention
// (ISO 230-7 style) is that the C-axis errors vanish at C = 0 (the per-angle route meets it when the A sweep is
// taken at C = 0 and the C sweep at A = 0).
#include <string>
#include <vector>

#include "cnccomp/deviations.hpp"
#include "cnccomp/identification/lsq.hpp"
#include "cnccomp/identification/rtest_run.hpp"

namespace cnccomp::identification {

struct AxisErrorSample {
    double angleDeg = 0;
    Vec3 delta = Vec3::Zero();  ///< δx δy δz, mm, axis (rotating) frame
    Vec3 xi = Vec3::Zero();     ///< ξx ξy ξz, rad
    int balls = 0;
    double rms = 0;             ///< RMS residual of the per-angle fit, mm
};

struct AxisErrors {
    std::string axis;
    std::vector<AxisErrorSample> samples;  ///< ascending angle
};

/// Per-angle six errors of the rotary axis `axis` (workpiece side) from the R-test runs that turn only that axis.
/// Assumes the tool side and the other axes are free of errors at the held positions. Throws ModelError when fewer
/// than three non-collinear balls see an angle, or no run turns the axis.
AxisErrors cradleAxisErrors(const MachineModel& m, const std::string& axis, const std::vector<measurement::RtestRun>& runs,
                            const std::vector<RtestTrace>& traces);

/// Component-error tables E[X|Y|Z|A|B|C]<axis> from per-angle results, node values interpolated linearly between
/// the measured angles (cyclically for a modulo axis). Throws ModelError for a missing table or uncovered node.
DeviationSet cradleDeviations(const MachineModel& m, const std::vector<AxisErrors>& errors);

/// Both axes by the per-angle route: the outer axis first (its sweeps hold the inner axis at 0, where the gauge puts
/// the inner errors at zero), then the inner axis after removing from its runs the displacement the identified outer
/// tables cause at the held outer position (exact model). `perAngle` receives the two per-angle results.
DeviationSet cradleTablesPerAngle(const MachineModel& m, const std::string& outerAxis, const std::string& innerAxis,
                             const std::vector<measurement::RtestRun>& runs, const std::vector<RtestTrace>& traces,
                             std::vector<AxisErrors>* perAngle = nullptr);

/// Six errors of one axis at one angle, for the small-angle model.
struct SixErrors {
    Vec3 delta = Vec3::Zero(), xi = Vec3::Zero();
};
/// Eq. (1)–(7): the workpiece point W_N (table frame) in the frame F (bed, origin at the A/C intersection) for the
/// nominal rotations about the unit directions `outerAxis` (A) and `innerAxis` (C), to first order in the errors.
Vec3 cradleSmallAngle(const Vec3& outerAxis, double alpha, const SixErrors& outer, const Vec3& innerAxis, double gamma,
                      const SixErrors& inner, const Vec3& pointInTable);

/// Least-squares equivalent: the twelve tables identified together by the engine from the raw displacements, then
/// moved to the gauge above by an exact change of frame (the engine leaves the unobservable directions at the
/// start; the report lists them).
struct CradleLsq {
    IdentificationReport report;
    DeviationSet deviations;  ///< after the gauge (the twelve tables present)
};
CradleLsq cradleLeastSquares(const MachineModel& m, const std::string& outerAxis, const std::string& innerAxis,
                             const std::vector<measurement::RtestRun>& runs, const std::vector<RtestTrace>& traces,
                             const IdentifyOptions& options = {});

}  // namespace cnccomp::identification
