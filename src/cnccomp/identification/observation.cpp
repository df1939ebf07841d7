#include "cnccomp/identification/observation.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include <fmt/format.h>

#include "cnccomp/error.hpp"

namespace cnccomp {

namespace {

Mat3 hat(const Vec3& w) {
    Mat3 m;
    m << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
    return m;
}

/// Left Jacobian of SO(3): exp(w + δ) = exp(Jl(w) δ) · exp(w) to first order. Exact, with series near 0.
Mat3 leftJacobian(const Vec3& w) {
    const double t = w.norm();
    double a, b;  // (1 − cos t)/t², (t − sin t)/t³
    if (t < 1e-3) {
        const double t2 = t * t;
        a = 0.5 - t2 / 24.0 + t2 * t2 / 720.0;
        b = 1.0 / 6.0 - t2 / 120.0 + t2 * t2 / 5040.0;
    } else {
        a = (1.0 - std::cos(t)) / (t * t);
        b = (t - std::sin(t)) / (t * t * t);
    }
    const Mat3 W = hat(w);
    return Mat3::Identity() + a * W + b * W * W;
}

/// Derivative of a point z = E · y (E = errorTransform(e), y fixed) with respect to e[c], in E's parent frame.
Vec3 errorTransformDerivative(const Vec6& e, const Mat3& Jl, int c, const Vec3& z) {
    if (c < 3) return Vec3::Unit(c);
    return (Jl * Vec3::Unit(c - 3)).cross(z - e.head<3>());
}

}  // namespace

DifferentiableMachine::DifferentiableMachine(const MachineModel& machine, const DeviationSet& deviations)
    : machine_(&machine), deviations_(deviations), kinematics_(machine, deviations_) {}

void DifferentiableMachine::bedPointJacobian(Side side, const AxisVector& q, const Vec3& point,
                                             const std::vector<int>& flat, Eigen::Ref<Eigen::MatrixXd> out) const {
    const MachineModel& m = *machine_;
    const Chain& chain = m.chain(side);
    const Eigen::VectorXd& v = deviations_.values;
    out.setZero();
    const int nLinks = static_cast<int>(chain.links.size());
    // Frames of every link: before the location error (after the placement) and before the component error
    // (after the motion), with the error vectors — the same composition as Kinematics::chainPose.
    constexpr int kMaxLinks = 32;
    if (nLinks > kMaxLinks) throw ModelError(fmt::format("machine '{}': chain longer than {} links", m.name, kMaxLinks));
    std::array<Pose, kMaxLinks> beforeLocation, beforeComponent;
    std::array<Vec6, kMaxLinks> location, component;
    Pose f = Pose::Identity();
    for (int i = 0; i < nLinks; ++i) {
        const Link& l = chain.links[i];
        location[i].setZero();
        component[i].setZero();
        const double qi = l.axisIndex >= 0 ? q[l.axisIndex] : 0.0;
        bool hasComponent = false;
        for (const DeviationDef& d : m.deviations) {
            if (d.side != side || d.link != i) continue;
            if (d.kind == DeviationKind::Location) {
                location[i][d.component] += v[d.offset];
            } else {
                component[i][d.component] += d.basis.evaluate(qi, v.data() + d.offset, l.modulo);
                hasComponent = true;
            }
        }
        f = f * l.placement;
        beforeLocation[i] = f;
        f = f * errorTransform(location[i]);
        if (l.kind == AxisKind::Linear) f.translation() += f.linear() * (l.direction * qi);
        else if (l.kind == AxisKind::Rotary) f.linear() = f.linear() * axisRotation(l.direction, qi);
        beforeComponent[i] = f;
        if (hasComponent) f = f * errorTransform(component[i]);
    }
    const Vec3 p = f * point;  // bed coordinates

    // Unit coefficient vectors for basis values without allocation: e_j of length n is unit.data() + n-1-j.
    for (size_t j = 0; j < flat.size(); ++j) {
        const int idx = flat[j];
        if (idx < 0 || idx >= static_cast<int>(v.size()))
            throw ModelError(fmt::format("parameter index {} outside the deviation vector", idx));
        // Which deviation owns this flat index.
        const DeviationDef* def = nullptr;
        for (const DeviationDef& d : m.deviations)
            if (idx >= d.offset && idx < d.offset + d.size()) { def = &d; break; }
        if (!def || def->side != side) continue;
        const int i = def->link;
        const Link& l = chain.links[i];
        if (def->kind == DeviationKind::Location) {
            const Pose& g = beforeLocation[i];
            const Vec3 z = g.inverse(Eigen::Isometry) * p;
            const Mat3 Jl = leftJacobian(location[i].tail<3>());
            out.col(j) = g.linear() * errorTransformDerivative(location[i], Jl, def->component, z);
        } else {
            const double qi = l.axisIndex >= 0 ? q[l.axisIndex] : 0.0;
            const int k = idx - def->offset;
            // basis_k(q): evaluate with the k-th unit coefficient vector.
            const int n = def->size();
            double coefStorage[64];
            std::vector<double> big;
            double* coef = coefStorage;
            if (n > 64) { big.assign(n, 0.0); coef = big.data(); }
            else std::fill(coef, coef + n, 0.0);
            coef[k] = 1.0;
            const double b = def->basis.evaluate(qi, coef, l.modulo);
            if (b == 0.0) continue;
            const Pose& g = beforeComponent[i];
            const Vec3 z = g.inverse(Eigen::Isometry) * p;
            const Mat3 Jl = leftJacobian(component[i].tail<3>());
            out.col(j) = b * (g.linear() * errorTransformDerivative(component[i], Jl, def->component, z));
        }
    }
}

void DifferentiableMachine::toolPointJacobian(const AxisVector& q, const Vec3& toolPoint, const std::vector<int>& flat,
                                              Eigen::Ref<Eigen::MatrixXd> out) const {
    // p_w = bMw⁻¹ · bMt · P:  ∂p_w = Rwᵀ (∂(bMt P) − ∂(bMw p_w)|p_w fixed).
    const Pose bMw = kinematics_.baseToWorkpiece(q);
    const Pose bMt = kinematics_.baseToTool(q);
    const Vec3 pBed = bMt * toolPoint;
    const Vec3 pW = bMw.inverse(Eigen::Isometry) * pBed;
    Eigen::MatrixXd jt(3, flat.size()), jw(3, flat.size());
    bedPointJacobian(Side::Tool, q, toolPoint, flat, jt);
    bedPointJacobian(Side::Workpiece, q, pW, flat, jw);
    out = bMw.linear().transpose() * (jt - jw);
}

// ---------------------------------------------------------------------------------------------------------------

BallbarObservation::BallbarObservation(const MachineModel& machine, BallbarRun run, const BallbarTrace& trace)
    : run_(std::move(run)) {
    run_.validate();
    if (trace.angleDeg.size() != trace.dL.size())
        throw ModelError(fmt::format("run '{}': trace has {} angles but {} ΔL values", run_.name,
                                     trace.angleDeg.size(), trace.dL.size()));
    if (trace.dL.empty()) throw ModelError(fmt::format("run '{}': trace has no samples", run_.name));
    const Kinematics nominal(machine);
    setup_ = setupCommands(machine, run_);
    try {
        nominal.checkTravel(setup_);
    } catch (const ModelError& e) {
        throw ModelError(fmt::format("run '{}' setup: {}", run_.name, e.what()));
    }
    measured_.resize(static_cast<Eigen::Index>(trace.dL.size()));
    anglesDeg_ = trace.angleDeg;
    commands_.reserve(trace.dL.size());
    for (size_t i = 0; i < trace.dL.size(); ++i) {
        if (!std::isfinite(trace.angleDeg[i]) || !std::isfinite(trace.dL[i]))
            throw ModelError(fmt::format("run '{}': sample {} is not a finite number", run_.name, i + 1));
        measured_[static_cast<Eigen::Index>(i)] = trace.dL[i];
        AxisVector q = runCommands(machine, run_, trace.angleDeg[i] * kDeg);
        try {
            nominal.checkTravel(q);
        } catch (const ModelError& e) {
            throw ModelError(fmt::format("run '{}' at {:g} deg: {}", run_.name, trace.angleDeg[i], e.what()));
        }
        commands_.push_back(q);
    }
}

int BallbarObservation::nuisanceCount() const {
    return (run_.estimateToolBallOffset ? 3 : 0) + (run_.estimateWorkBallOffset ? 3 : 0);
}

std::vector<std::string> BallbarObservation::nuisanceNames() const {
    std::vector<std::string> n;
    if (run_.estimateToolBallOffset)
        for (const char* c : {"xT", "yT", "zT"}) n.push_back(run_.name + "." + c);
    if (run_.estimateWorkBallOffset)
        for (const char* c : {"xW", "yW", "zW"}) n.push_back(run_.name + "." + c);
    return n;
}

void BallbarObservation::nuisanceInitial(double* out) const {
    int k = 0;
    if (run_.estimateToolBallOffset)
        for (int i = 0; i < 3; ++i) out[k++] = run_.toolBallOffset[i];
    if (run_.estimateWorkBallOffset)
        for (int i = 0; i < 3; ++i) out[k++] = run_.workBallOffset[i];
}

void BallbarObservation::offsets(const double* nuisance, Vec3& tool, Vec3& work) const {
    tool = run_.toolBallOffset;
    work = run_.workBallOffset;
    int k = 0;
    if (run_.estimateToolBallOffset) { tool = Vec3(nuisance[0], nuisance[1], nuisance[2]); k = 3; }
    if (run_.estimateWorkBallOffset) work = Vec3(nuisance[k], nuisance[k + 1], nuisance[k + 2]);
}

void BallbarObservation::predict(const Kinematics& k, const double* nuisance, double* out) const {
    Vec3 toolOff, workOff;
    offsets(nuisance, toolOff, workOff);
    const Vec3 tBall = k.toolPoint(run_.RB, toolOff);                          // eq. (15)
    const Vec3 wBall = k.toolPointInWorkpiece(setup_, tBall) + workOff;       // eq. (11)–(13), (16)
    for (size_t i = 0; i < commands_.size(); ++i)
        out[i] = (k.toolPointInWorkpiece(commands_[i], tBall) - wBall).norm() - run_.LB;  // eq. (14)
}

bool BallbarObservation::jacobian(const DifferentiableMachine& m, const double* nuisance, const std::vector<int>& flat,
                                  Eigen::Ref<Eigen::MatrixXd> J) const {
    const Kinematics& k = m.kinematics();
    Vec3 toolOff, workOff;
    offsets(nuisance, toolOff, workOff);
    const Vec3 tBall = k.toolPoint(run_.RB, toolOff);
    const Pose w0 = k.workpieceToTool(setup_);
    const Vec3 wBall = w0 * tBall + workOff;
    const int np = static_cast<int>(flat.size());
    Eigen::MatrixXd j0(3, np), ji(3, np);
    m.toolPointJacobian(setup_, tBall, flat, j0);
    for (size_t i = 0; i < commands_.size(); ++i) {
        const Pose wi = k.workpieceToTool(commands_[i]);
        const Vec3 d = wi * tBall - wBall;
        const Vec3 n = d / d.norm();
        m.toolPointJacobian(commands_[i], tBall, flat, ji);
        const auto row = static_cast<Eigen::Index>(i);
        J.row(row).head(np) = n.transpose() * (ji - j0);
        int c = np;
        if (run_.estimateToolBallOffset) {
            J.row(row).segment<3>(c) = n.transpose() * (wi.linear() - w0.linear());
            c += 3;
        }
        if (run_.estimateWorkBallOffset) J.row(row).segment<3>(c) = -n.transpose();
    }
    return true;
}

Observations ballbarObservations(const MachineModel& machine, const std::vector<BallbarRun>& runs,
                                 const std::vector<BallbarTrace>& traces) {
    if (runs.size() != traces.size())
        throw ModelError(fmt::format("{} runs but {} traces", runs.size(), traces.size()));
    Observations obs;
    for (size_t i = 0; i < runs.size(); ++i)
        obs.push_back(std::make_unique<BallbarObservation>(machine, runs[i], traces[i]));
    return obs;
}

}  // namespace cnccomp
