#include "cnccomp/identification/dbb5_observation.hpp"

#include <cmath>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/identification/plan_method.hpp"

namespace cnccomp::identification {
using namespace cnccomp::measurement;

Dbb5Observation::Dbb5Observation(const MachineModel& machine, Dbb5Run run, const BallbarTrace& trace)
    : run_(std::move(run)) {
    run_.validate();
    if (trace.angleDeg.size() != trace.dL.size() || trace.dL.empty())
        throw ModelError(fmt::format("DBB5 run '{}': trace has {} angles and {} ΔL values", run_.name,
                                     trace.angleDeg.size(), trace.dL.size()));
    const Kinematics nominal(machine);
    setup_ = dbb5SetupCommands(machine, run_);
    anglesDeg_ = trace.angleDeg;
    if (run_.kind == Dbb5Run::Kind::RotaryCircle) {
        turning_ = {run_.axis};
    } else if (run_.kind == Dbb5Run::Kind::ConeFrustum) {
        const auto [outer, inner] = tableRotaryAxes(machine);
        for (const std::string& a : {outer, inner})
            if (!a.empty()) turning_.push_back(a);
    }
    measured_.resize(static_cast<Eigen::Index>(trace.dL.size()));
    for (size_t i = 0; i < trace.dL.size(); ++i) {
        if (!std::isfinite(trace.angleDeg[i]) || !std::isfinite(trace.dL[i]))
            throw ModelError(fmt::format("DBB5 run '{}': sample {} is not a finite number", run_.name, i + 1));
        measured_[static_cast<Eigen::Index>(i)] = trace.dL[i];
        const AxisVector q = dbb5Commands(machine, run_, trace.angleDeg[i]);
        try {
            nominal.checkTravel(q);
        } catch (const ModelError& e) {
            throw ModelError(fmt::format("DBB5 run '{}' at {:g} deg: {}", run_.name, trace.angleDeg[i], e.what()));
        }
        commands_.push_back(q);
    }
}

void Dbb5Observation::predict(const Kinematics& k, const double* /*nuisance*/, double* out) const {
    const Vec3 spindle = k.toolPoint(run_.toolLength);
    const Vec3 table = k.toolPointInWorkpiece(setup_, spindle);
    for (size_t i = 0; i < commands_.size(); ++i)
        out[i] = (k.toolPointInWorkpiece(commands_[i], spindle) - table).norm() - run_.LB;
}

bool Dbb5Observation::jacobian(const DifferentiableMachine& m, const double* /*nuisance*/, const std::vector<int>& flat,
                               Eigen::Ref<Eigen::MatrixXd> J) const {
    const Kinematics& k = m.kinematics();
    const Vec3 spindle = k.toolPoint(run_.toolLength);
    const Vec3 table = k.toolPointInWorkpiece(setup_, spindle);
    const int np = static_cast<int>(flat.size());
    Eigen::MatrixXd j0(3, np), ji(3, np);
    m.toolPointJacobian(setup_, spindle, flat, j0);
    for (size_t i = 0; i < commands_.size(); ++i) {
        const Vec3 d = k.toolPointInWorkpiece(commands_[i], spindle) - table;
        m.toolPointJacobian(commands_[i], spindle, flat, ji);
        J.row(static_cast<Eigen::Index>(i)).head(np) = (d / d.norm()).transpose() * (ji - j0);
    }
    return true;
}

Observations dbb5Observations(const MachineModel& machine, const std::vector<Dbb5Run>& runs,
                              const std::vector<BallbarTrace>& traces) {
    if (runs.size() != traces.size())
        throw ModelError(fmt::format("{} DBB5 runs but {} traces", runs.size(), traces.size()));
    Observations obs;
    for (size_t i = 0; i < runs.size(); ++i)
        obs.push_back(std::make_unique<Dbb5Observation>(machine, runs[i], traces[i]));
    return obs;
}

}  // namespace cnccomp::identification
