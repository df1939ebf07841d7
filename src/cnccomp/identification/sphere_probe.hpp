#pragma once
// Commands, simulation and observations of touch-probe runs on a calibration sphere (measurement/sphere_run.hpp).
//
// Commands (every position the program goes to, on the nominal machine, description frame):
//   per pose: the rotary axes at the pose's angles; the stylus ball centre (tool point at the run's tool length)
//   - at the safe point S = c + (R + clearance)·u above the pole (u: unit vector from the sphere centre c towards the
//     spindle along the tool axis, R = sphere + stylus radius);
//   - per touch with outward normal n (touch 0: n = u, the pole; touches 1..N: the ring at the latitude, the first
//     along the tool frame's +X, counter-clockwise about u): "above" A = the point over the approach point at S's
//     height along u, approach P = c + (R + approach)·n, target T = c + (R − approach)·n; the probing move goes from
//     P to T and stops at the trigger, then the program goes back to P, up to A and on to the next touch's A (all
//     these moves stay at least `clearance` clear of the sphere: A and S lie in the plane at R + clearance along u);
//   - between poses the linear axis along the tool direction ("park axis") goes to the park value (beyond every
//     pose's safe point by the largest clearance, inside its travel), the other axes move together to the next pose,
//     the park axis comes back down to the next safe point. The move at the park value is checked at 64 points to stay
//     half a clearance clear of every sphere of the plan.
// Every command is checked against the travel; errors name the run, the pose (number from 0 in the plan and angles)
// and the touch.
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "cnccomp/identification/observation.hpp"
#include "cnccomp/kinematics.hpp"
#include "cnccomp/measurement/probe_log.hpp"
#include "cnccomp/measurement/sphere_run.hpp"

namespace cnccomp::identification {

struct SphereTouchCommand {
    Vec3 normal = Vec3::UnitZ();  ///< outward surface normal at the nominal touch, workpiece frame
    AxisVector above, approach, target;
};

struct SpherePoseCommand {
    int planPose = 0;             ///< pose number in the plan (from 0, over every sphere run)
    measurement::SpherePose angles;            ///< as planned (deg)
    AxisVector safe;              ///< stylus at the safe point above the pole
    std::vector<SphereTouchCommand> touches;  ///< pole first, then the ring
};

struct SphereRunCommands {
    measurement::SphereRun run;
    std::vector<SpherePoseCommand> poses;
};

struct SpherePlanCommands {
    std::vector<SphereRunCommands> runs;
    int parkAxis = -1;            ///< linear axis along the tool direction
    double parkValue = 0;         ///< its value for the moves between poses (mm)
    int poseCount() const;
};

/// Root of f in [lo, hi] with f(lo) > 0 >= f(hi) (Illinois regula falsi: the retained end's value halved when the same
/// end is kept twice; |f| < 1e-14 or an interval under 1e-15 ends it); nullopt when f does not change sign there. The
/// point of a probing move where the stylus ball reaches the sphere: f(t) = |ball(t) - sphere| - radius.
std::optional<double> bracketedRoot(const std::function<double(double)>& f, double lo, double hi);

/// Commands of every sphere run of a plan (pose numbers continue from run to run). Throws ModelError naming the run,
/// pose and touch for a command outside the travel or a move between poses that would come near a sphere.
SpherePlanCommands sphereCommands(const MachineModel& machine, const std::vector<measurement::SphereRun>& runs);

/// Tool point of the stylus ball centre (tool frame).
Vec3 stylusPoint(const MachineModel& machine, const measurement::SphereRun& run);

/// Where the probing move from `from` to `to` (straight in the axes) triggers on machine `k`: the first point at which
/// the stylus ball centre is `radius` from `sphere` (workpiece frame). Parameter along the move in [lo, hi] (0 = from,
/// 1 = to); nullopt when the move does not reach the sphere in that range (a missed touch).
std::optional<AxisVector> probeTrigger(const Kinematics& k, const Vec3& stylus, const AxisVector& from, const AxisVector& to,
                                       const Vec3& sphere, double radius, double lo = 0.0, double hi = 1.0);

/// The log a machine `k` would write for the plan's sphere runs: each run's sphere at centre + sphereOffset, the
/// probe triggering at trigger offset triggerOffset + triggerError; `noise` (mm, one standard deviation) moves each
/// trigger along its probing move with normal noise from `seed` (0 = none). Missed touches are recorded with
/// triggered = 0 at the target, as G38.3 leaves them.
measurement::ProbeLog simulateSphereProbing(const Kinematics& k, const SpherePlanCommands& commands, double noise = 0.0,
                               unsigned long seed = 1);

/// The touches of each pose of each run from a log, checked: every (pose, touch) of the plan once, triggered, its
/// rotary axes at the pose's angles (1e-3 deg) and its stylus ball centre within the run's window of the nominal
/// surface. Throws InputError (log file, line) naming the pose and touch otherwise, or (line 0) a touch that is not in
/// the file. Result: [run][pose][touch] axis positions, description frame.
std::vector<std::vector<std::vector<AxisVector>>> checkedTouches(const MachineModel& machine,
                                                                 const SpherePlanCommands& commands, const measurement::ProbeLog& log);

/// Observation of one sphere run: per pose the fitted sphere centre (fitSphereKnownRadius on the stylus ball centres
/// the nominal machine computes from the touch positions) minus the nominal centre, workpiece frame, 3 values a pose.
/// predict() simulates every touch of the run on the machine at the current deviations (probeTrigger along the
/// commanded probing moves, sphere at centre + offset, the probe's trigger offset) and fits it the same way, so the
/// prediction is exact (no small-error approximation). Nuisance parameters: the sphere's offset (xSphere ySphere
/// zSphere, mm) and, when the run says so, its trigger offset (trigger, mm) shared by every pose. Jacobian: numerical.
class SphereObservation final : public ObservationModel {
public:
    SphereObservation(const MachineModel& machine, const SphereRunCommands& commands,
                      const std::vector<std::vector<AxisVector>>& touches);

    std::string runName() const override { return cmd_.run.name; }
    std::string kind() const override { return "sphere"; }
    int size() const override { return static_cast<int>(measured_.size()); }
    const Eigen::VectorXd& measured() const override { return measured_; }
    int nuisanceCount() const override { return cmd_.run.estimateTrigger ? 4 : 3; }
    std::vector<std::string> nuisanceNames() const override;
    void nuisanceInitial(double* out) const override;
    void predict(const Kinematics& k, const double* nuisance, double* out) const override;
    std::vector<std::string> turningAxes() const override;

    /// The fitted centres' residuals (rms of each pose's fit, mm), in pose order.
    const std::vector<double>& fitRms() const { return fitRms_; }

private:
    const MachineModel* machine_;
    Kinematics nominal_;
    SphereRunCommands cmd_;
    Vec3 stylus_;
    Eigen::VectorXd measured_;
    std::vector<double> fitRms_;
};

/// One observation per sphere run.
Observations sphereObservations(const MachineModel& machine, const SpherePlanCommands& commands, const measurement::ProbeLog& log);

}  // namespace cnccomp::identification
