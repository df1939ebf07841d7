#include "cnccomp/identification/observation.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include <fmt/format.h>

#include "cnccomp/error.hpp"

namespace cnccomp::identification {

namespace {


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
    const Mat3 W = skew(w);
    return Mat3::Identity() + a * W + b * W * W;
}

/// Derivative of a point z = E · y (E = errorTransform(e), y fixed) with respect to e[c], in E's parent frame.
Vec3 errorTransformDerivative(const Vec6& e, const Mat3& Jl, int c, const Vec3& z) {
    if (c < 3) return Vec3::Unit(c);
    return (Jl * Vec3::Unit(c - 3)).cross(z - e.head<3>());
}

}  // namespace

constexpr int kMaxLinks = 16;

/// Frames of every link of one chain at commands q: before the location error (after the placement) and before
/// the component error (after the motion), with the component error vectors — the same composition as
/// Kinematics::chainPose.
struct DifferentiableMachine::Frames {
    std::array<Pose, kMaxLinks> beforeLocation, beforeComponent;
    std::array<Vec6, kMaxLinks> component;
    std::array<double, kMaxLinks> q;
    Pose end = Pose::Identity();
};

DifferentiableMachine::DifferentiableMachine(const MachineModel& machine, const DeviationSet& deviations)
    : machine_(&machine), deviations_(deviations), kinematics_(machine, deviations_) {
    const Eigen::VectorXd& v = deviations_.values;
    owner_.assign(static_cast<size_t>(v.size()), FlatOwner{});
    for (int k = 0; k < static_cast<int>(machine.deviations.size()); ++k) {
        const DeviationDef& d = machine.deviations[k];
        for (int c = 0; c < d.size(); ++c) owner_[d.offset + c] = {k, c};
    }
    for (Side side : {Side::Workpiece, Side::Tool}) {
        const Chain& chain = machine.chain(side);
        if (chain.links.size() > static_cast<size_t>(kMaxLinks))
            throw ModelError(fmt::format("machine '{}': chain longer than {} links", machine.name, kMaxLinks));
        auto& links = side == Side::Tool ? tool_ : workpiece_;
        links.assign(chain.links.size(), LinkConstants{});
        for (const DeviationDef& d : machine.deviations) {
            if (d.side != side) continue;
            if (d.kind == DeviationKind::Location) links[d.link].location[d.component] += v[d.offset];
            else links[d.link].hasComponent = true;
        }
        for (LinkConstants& l : links) l.locationJl = leftJacobian(l.location.tail<3>());
    }
}

void DifferentiableMachine::chainFrames(Side side, const AxisVector& q, Frames& f) const {
    const MachineModel& m = *machine_;
    const Chain& chain = m.chain(side);
    const auto& consts = side == Side::Tool ? tool_ : workpiece_;
    const Eigen::VectorXd& v = deviations_.values;
    Pose p = Pose::Identity();
    for (size_t i = 0; i < chain.links.size(); ++i) {
        const Link& l = chain.links[i];
        const double qi = l.axisIndex >= 0 ? q[l.axisIndex] : 0.0;
        f.q[i] = qi;
        p = p * l.placement;
        f.beforeLocation[i] = p;
        p = p * errorTransform(consts[i].location);
        if (l.kind == AxisKind::Linear) p.translation() += p.linear() * (l.direction * qi);
        else if (l.kind == AxisKind::Rotary) p.linear() = p.linear() * axisRotation(l.direction, qi);
        f.beforeComponent[i] = p;
        f.component[i].setZero();
        if (consts[i].hasComponent) {
            for (const DeviationDef& d : m.deviations)
                if (d.side == side && d.link == static_cast<int>(i) && d.kind == DeviationKind::Component)
                    f.component[i][d.component] += d.basis.evaluate(qi, v.data() + d.offset, l.modulo);
            p = p * errorTransform(f.component[i]);
        }
    }
    f.end = p;
}

void DifferentiableMachine::chainDerivative(Side side, const Frames& f, const Vec3& pBed, int idx, Vec3& out) const {
    const FlatOwner& o = owner_[idx];
    const DeviationDef& def = machine_->deviations[o.deviation];
    const auto& consts = side == Side::Tool ? tool_ : workpiece_;
    const int i = def.link;
    if (def.kind == DeviationKind::Location) {
        const Pose& g = f.beforeLocation[i];
        const Vec3 z = g.linear().transpose() * (pBed - g.translation());
        out = g.linear() * errorTransformDerivative(consts[i].location, consts[i].locationJl, def.component, z);
        return;
    }
    // basis_k(q): evaluate with the k-th unit coefficient vector (e_k of length n is unit + n − 1 − k).
    const int n = def.size();
    static thread_local std::vector<double> unit;
    if (static_cast<int>(unit.size()) < 2 * n - 1) {
        unit.assign(2 * static_cast<size_t>(n) - 1, 0.0);
        unit[n - 1] = 1.0;
    }
    std::fill(unit.begin(), unit.end(), 0.0);
    unit[n - 1] = 1.0;
    const double b = def.basis.evaluate(f.q[i], unit.data() + (n - 1 - o.coefficient), machine_->chain(side).links[i].modulo);
    if (b == 0.0) {
        out.setZero();
        return;
    }
    const Pose& g = f.beforeComponent[i];
    const Vec3 z = g.linear().transpose() * (pBed - g.translation());
    const Mat3 Jl = leftJacobian(f.component[i].tail<3>());
    out = b * (g.linear() * errorTransformDerivative(f.component[i], Jl, def.component, z));
}

void DifferentiableMachine::bedPointJacobian(Side side, const AxisVector& q, const Vec3& point,
                                             const std::vector<int>& flat, Eigen::Ref<Eigen::MatrixXd> out) const {
    Frames f;
    chainFrames(side, q, f);
    const Vec3 pBed = f.end * point;
    Vec3 d;
    for (size_t j = 0; j < flat.size(); ++j) {
        const int idx = flat[j];
        if (idx < 0 || idx >= static_cast<int>(owner_.size()))
            throw ModelError(fmt::format("parameter index {} outside the deviation vector", idx));
        if (machine_->deviations[owner_[idx].deviation].side != side) {
            out.col(j).setZero();
            continue;
        }
        chainDerivative(side, f, pBed, idx, d);
        out.col(j) = d;
    }
}

void DifferentiableMachine::toolPointJacobian(const AxisVector& q, const Vec3& toolPoint, const std::vector<int>& flat,
                                              Eigen::Ref<Eigen::MatrixXd> out) const {
    // p_w = bMw⁻¹ · bMt · P. A tool-chain parameter moves the bed point p = bMt·P: ∂p_w = Rwᵀ ∂p. A workpiece-chain
    // parameter moves the workpiece frame: ∂p_w = −Rwᵀ ∂(bMw·p_w)|p_w fixed, and bMw·p_w is the same bed point p.
    Frames ft, fw;
    chainFrames(Side::Tool, q, ft);
    chainFrames(Side::Workpiece, q, fw);
    const Vec3 pBed = ft.end * toolPoint;
    const Mat3 RwT = fw.end.linear().transpose();
    Vec3 d;
    for (size_t j = 0; j < flat.size(); ++j) {
        const int idx = flat[j];
        if (idx < 0 || idx >= static_cast<int>(owner_.size()))
            throw ModelError(fmt::format("parameter index {} outside the deviation vector", idx));
        const Side side = machine_->deviations[owner_[idx].deviation].side;
        chainDerivative(side, side == Side::Tool ? ft : fw, pBed, idx, d);
        out.col(j) = side == Side::Tool ? Vec3(RwT * d) : Vec3(-(RwT * d));
    }
}

// ---------------------------------------------------------------------------------------------------------------

std::vector<std::string> BallbarObservation::turningAxes() const {
    return {rotatesHead(run_.test) ? run_.headAxis : run_.tableAxis};
}

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

}  // namespace cnccomp::identification
