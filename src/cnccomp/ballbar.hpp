#pragma once
// Double-ball-bar runs of [MultiTasking] (Table 2) and their simulation on an exact machine model (eq. (14)–(16)).
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cnccomp/kinematics.hpp"
#include "cnccomp/run_capture.hpp"

namespace cnccomp {

/// The twelve measurement types of [MultiTasking] Table 2: B/C axis radial, tangential, axial (cylindrical)
/// and X/Y/Z-direction (Cartesian).
enum class BallbarTest { BX, BY, BZ, CRadial, CTangential, CAxial, CX, CY, CZ, BRadial, BTangential, BAxial };

inline constexpr BallbarTest kAllBallbarTests[] = {
    BallbarTest::BX, BallbarTest::BY, BallbarTest::BZ, BallbarTest::CRadial, BallbarTest::CTangential,
    BallbarTest::CAxial, BallbarTest::CX, BallbarTest::CY, BallbarTest::CZ, BallbarTest::BRadial,
    BallbarTest::BTangential, BallbarTest::BAxial};

/// "B-X", "C-radial", …
std::string_view testName(BallbarTest t);
std::optional<BallbarTest> parseTest(std::string_view s);
/// True when the head rotary axis (B) moves; false when the table axis (C) moves.
bool rotatesHead(BallbarTest t);

/// One ball-bar run: its type, geometry ([MultiTasking] section 4 names) and angular sweep.
struct BallbarRun {
    std::string name;
    BallbarTest test = BallbarTest::BX;
    double LB = 100.0;  ///< ball bar length, mm
    double RB = 200.0;  ///< B rotation centre → T-side ball, mm (tool length)
    double RC = 50.0;   ///< C axis → W-side ball, mm
    double ZC = 100.0;  ///< C table surface → W-side ball, mm
    double startDeg = 0.0, endDeg = 360.0, stepDeg = 1.0;
    Vec3 toolBallOffset = Vec3::Zero();  ///< (xT, yT, zT) of eq. (15), mm, tool frame
    Vec3 workBallOffset = Vec3::Zero();  ///< (xW, yW, zW) of eq. (16), mm, workpiece frame
    bool estimateToolBallOffset = false;  ///< identification: treat (xT, yT, zT) as nuisance parameters
    bool estimateWorkBallOffset = false;  ///< identification: treat (xW, yW, zW) as nuisance parameters
    std::string headAxis = "B";
    std::string tableAxis = "C";
    RunCapture capture;  ///< how the measured trace was recorded and exported (defaults: cnccomp's own traces)

    /// Sweep angles in degrees; a full turn does not repeat its first angle.
    std::vector<double> anglesDeg() const;
    /// Throws ModelError when the geometry is impossible (non-positive LB, zero step, NaN …).
    void validate() const;
};

/// Axis commands of Table 2 at sweep angle `angle` (rad).
AxisVector runCommands(const MachineModel& m, const BallbarRun& run, double angle);
/// Axis commands at which the W-side ball is set on the T-side ball (eq. (11), (12)).
AxisVector setupCommands(const MachineModel& m, const BallbarRun& run);

struct BallbarTrace {
    std::vector<double> angleDeg;
    std::vector<double> dL;  ///< ΔL = L − LB, mm (eq. (14))
};

/// Maps the commands a program asks for to the commands the drives receive (a compensation); identity if empty.
using CommandMap = std::function<AxisVector(const AxisVector&)>;

/// Simulates a run: sets the W-side ball where the T-side ball is at the setup commands, then ΔL along the
/// sweep. With `drive`, every command (setup included) passes through it first, as a compensating controller would.
/// Throws ModelError if a command leaves an axis' travel.
BallbarTrace simulateRun(const Kinematics& machine, const BallbarRun& run, const CommandMap& drive = {});

/// Unit vectors (u, v) of the plane of the run's rotary axis, angle 0 along u, 90° along v (cyclic:
/// C about Z → (X, Y); B about Y → (Z, X)), and the index of the out-of-plane machine axis.
struct RunPlane {
    Vec3 u, v;
    int normalIndex;
};
RunPlane runPlane(const MachineModel& m, const BallbarRun& run);

/// Eccentricity (ex, ey, ez) in mm of a trace: centre of the least-squares circle fitted to the polar
/// trajectory (LB + ΔL) at the sweep angle, in the plane of the rotary axis. The out-of-plane component
/// is NaN. Sign convention: a trajectory shifted towards +X has ex > 0 ([MultiTasking] Table 5 holds).
Vec3 traceEccentricity(const MachineModel& m, const BallbarRun& run, const BallbarTrace& trace);

}  // namespace cnccomp
