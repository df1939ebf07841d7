#include "cnccomp/identification/eccentricity_observation.hpp"

#include <cmath>

#include <fmt/format.h>

#include "cnccomp/error.hpp"

namespace cnccomp::identification {

EccentricityObservation::EccentricityObservation(const MachineModel& machine, BallbarRun run, const BallbarTrace& trace)
    : run_(std::move(run)), anglesDeg_(trace.angleDeg), measured_(2) {
    if (run_.estimateToolBallOffset || run_.estimateWorkBallOffset)
        throw ModelError(fmt::format("run '{}': mounting offsets cannot be estimated from an eccentricity", run_.name));
    const Kinematics nominal(machine);
    try {
        nominal.checkTravel(setupCommands(machine, run_));
        for (double a : anglesDeg_) nominal.checkTravel(runCommands(machine, run_, a * kDeg));
    } catch (const ModelError& e) {
        throw ModelError(fmt::format("run '{}': {}", run_.name, e.what()));
    }
    plane_ = runPlane(machine, run_);
    Vec3 e = traceEccentricity(machine, run_, trace);
    e[plane_.normalIndex] = 0.0;  // the out-of-plane component is not defined (NaN)
    measured_ << e.dot(plane_.u), e.dot(plane_.v);
    if (!measured_.allFinite()) throw ModelError(fmt::format("run '{}': eccentricity is not finite", run_.name));
    weight_ = std::sqrt(static_cast<double>(trace.dL.size()) / 2.0);
}

void EccentricityObservation::predict(const Kinematics& k, const double*, double* out) const {
    const BallbarRun& r = run_;
    BallbarTrace t;  // the run simulated at the measured angles (as simulateRun does)
    t.angleDeg = anglesDeg_;
    t.dL.resize(anglesDeg_.size());
    const Vec3 tBall = k.toolPoint(r.RB, r.toolBallOffset);
    const Vec3 wBall = k.toolPointInWorkpiece(setupCommands(k.machine(), r), tBall) + r.workBallOffset;
    for (size_t i = 0; i < anglesDeg_.size(); ++i)
        t.dL[i] = (k.toolPointInWorkpiece(runCommands(k.machine(), r, anglesDeg_[i] * kDeg), tBall) - wBall).norm() - r.LB;
    Vec3 e = traceEccentricity(k.machine(), r, t);
    e[plane_.normalIndex] = 0.0;
    out[0] = e.dot(plane_.u);
    out[1] = e.dot(plane_.v);
}

Observations eccentricityObservations(const MachineModel& machine, const std::vector<BallbarRun>& runs,
                                      const std::vector<BallbarTrace>& traces) {
    if (runs.size() != traces.size()) throw ModelError(fmt::format("{} runs but {} traces", runs.size(), traces.size()));
    Observations obs;
    for (size_t i = 0; i < runs.size(); ++i)
        obs.push_back(std::make_unique<EccentricityObservation>(machine, runs[i], traces[i]));
    return obs;
}

}  // namespace cnccomp::identification
