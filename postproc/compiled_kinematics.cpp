#include "postproc/compiled_kinematics.hpp"

#include <cmath>

namespace cnccomp::pp {

namespace {

bool isIdentity(const Mat3& R, const Vec3& t) { return R == Mat3::Identity() && t == Vec3::Zero(); }

/// R ← R · Rot(unit axis k, angle): two columns change.
inline void rotateAboutUnit(Mat3& R, int k, double angle) {
    const double c = std::cos(angle), s = std::sin(angle);
    const int i = (k + 1) % 3, j = (k + 2) % 3;  // Rx: (y, z), Ry: (z, x), Rz: (x, y)
    const Vec3 a = R.col(i), b = R.col(j);
    R.col(i) = c * a + s * b;
    R.col(j) = c * b - s * a;
}

}  // namespace

CompiledKinematics::CompiledKinematics(const MachineModel& machine, const DeviationSet* deviations)
    : machine_(&machine),
      values_(deviations ? deviations->values : Eigen::VectorXd::Zero(machine.parameterCount())) {
    compile(machine.workpiece, Side::Workpiece, workpiece_, workpieceAxes_);
    compile(machine.tool, Side::Tool, tool_, toolAxes_);
}

void CompiledKinematics::compile(const Chain& chain, Side side, std::vector<Op>& ops, std::vector<int>& axes) {
    ops.clear();
    axes.clear();
    Frame pending;  // constant transforms not emitted yet
    auto flush = [&]() {
        if (isIdentity(pending.R, pending.t)) return;
        Op op;
        op.kind = OpKind::Constant;
        op.R = pending.R;
        op.t = pending.t;
        ops.push_back(op);
        pending = Frame{};
    };
    for (int i = 0; i < static_cast<int>(chain.links.size()); ++i) {
        const Link& l = chain.links[i];
        Vec6 location = Vec6::Zero();
        std::vector<int> components;
        for (int k = 0; k < static_cast<int>(machine_->deviations.size()); ++k) {
            const DeviationDef& def = machine_->deviations[k];
            if (def.side != side || def.link != i) continue;
            if (def.kind == DeviationKind::Location) {
                location[def.component] += values_[def.offset];
            } else {
                bool any = false;
                for (int c = 0; c < def.size(); ++c) any = any || values_[def.offset + c] != 0.0;
                if (any) components.push_back(k);
            }
        }
        const Pose placed = l.placement * errorTransform(location);
        // pending ← pending · placed
        pending.t = pending.R * placed.translation() + pending.t;
        pending.R = pending.R * placed.linear();
        if (l.kind == AxisKind::Fixed) continue;
        axes.push_back(l.axisIndex);
        flush();
        Op op;
        op.kind = l.kind == AxisKind::Linear ? OpKind::Linear : OpKind::Rotary;
        op.axis = l.axisIndex;
        op.dir = l.direction;
        op.modulo = l.modulo;
        for (int k = 0; k < 3; ++k)
            if (l.direction == Vec3::Unit(k)) op.unit = k;
        ops.push_back(op);
        if (!components.empty()) {
            Op c;
            c.kind = OpKind::Component;
            c.axis = l.axisIndex;
            c.modulo = l.modulo;
            c.components = std::move(components);
            ops.push_back(std::move(c));
        }
    }
    flush();
}

void CompiledKinematics::evaluate(const std::vector<Op>& ops, const AxisVector& q, Frame& f, Lines* lines) const {
    f.R.setIdentity();
    f.t.setZero();
    for (const Op& op : ops) {
        switch (op.kind) {
            case OpKind::Constant:
                f.t += f.R * op.t;
                f.R = f.R * op.R;
                break;
            case OpKind::Linear:
                if (lines) lines->items[lines->count++] = {op.axis, false, f.R * op.dir, f.t};
                f.t += f.R * (op.dir * q[op.axis]);
                break;
            case OpKind::Rotary:
                if (lines) lines->items[lines->count++] = {op.axis, true, f.R * op.dir, f.t};
                if (op.unit >= 0) rotateAboutUnit(f.R, op.unit, q[op.axis]);
                else f.R = f.R * axisRotation(op.dir, q[op.axis]);
                break;
            case OpKind::Component: {
                Vec6 e = Vec6::Zero();
                for (int k : op.components) {
                    const DeviationDef& def = machine_->deviations[k];
                    e[def.component] += def.basis.evaluate(q[op.axis], values_.data() + def.offset, op.modulo);
                }
                const Pose E = errorTransform(e);
                f.t += f.R * E.translation();
                f.R = f.R * E.linear();
                break;
            }
        }
    }
}

void CompiledKinematics::cached(const std::vector<Op>& ops, const std::vector<int>& axes, ChainCache& cache,
                                const AxisVector& q, Frame& f, Lines* lines) const {
    bool hit = cache.valid && (cache.hasLines || !lines);
    for (size_t k = 0; k < axes.size() && hit; ++k) hit = cache.key[k] == q[axes[k]];
    if (hit) {
        f = cache.frame;
        if (lines) {
            for (int k = 0; k < cache.lines.count; ++k) lines->items[lines->count++] = cache.lines.items[k];
        }
        return;
    }
    if (lines) {
        cache.lines.count = 0;
        evaluate(ops, q, f, &cache.lines);
        for (int k = 0; k < cache.lines.count; ++k) lines->items[lines->count++] = cache.lines.items[k];
    } else {
        evaluate(ops, q, f, nullptr);
    }
    cache.frame = f;
    cache.hasLines = lines != nullptr;
    cache.valid = true;
    for (size_t k = 0; k < axes.size(); ++k) cache.key[k] = q[axes[k]];
}

void CompiledKinematics::toolPose(const AxisVector& q, double length, Vec3& tip, Vec3& axis) const {
    Frame w, t;
    cached(workpiece_, workpieceAxes_, workpieceCache_, q, w, nullptr);
    cached(tool_, toolAxes_, toolCache_, q, t, nullptr);
    const Vec3 dirB = t.R * machine_->toolDirection;
    tip = w.R.transpose() * (t.t + length * dirB - w.t);
    axis = w.R.transpose() * dirB;
}

Vec3 CompiledKinematics::toolTip(const AxisVector& q, double length) const {
    Vec3 tip, axis;
    toolPose(q, length, tip, axis);
    return tip;
}

void CompiledKinematics::jacobian(const AxisVector& q, double length, PoseJacobian& J, Vec3& tip, Vec3& axis) const {
    Lines lines;
    Frame w, t;
    cached(workpiece_, workpieceAxes_, workpieceCache_, q, w, &lines);
    const int workpieceLines = lines.count;
    cached(tool_, toolAxes_, toolCache_, q, t, &lines);
    const Vec3 dirB = t.R * machine_->toolDirection;
    const Vec3 tipB = t.t + length * dirB;
    const Mat3 wRb = w.R.transpose();
    tip = wRb * (tipB - w.t);
    axis = wRb * dirB;
    J.setZero(6, q.size());
    for (int k = 0; k < lines.count; ++k) {
        const JointLine& j = lines.items[k];
        // Tool-side motion moves the tool; workpiece-side motion moves the workpiece, i.e. the tool relative to it
        // the other way (as cnccomp::toolPoseJacobian; component errors' own slopes are neglected).
        const double sign = k < workpieceLines ? -1.0 : 1.0;
        if (j.rotary) {
            J.block<3, 1>(0, j.axis) = sign * (wRb * j.direction.cross(tipB - j.point));
            J.block<3, 1>(3, j.axis) = sign * (wRb * j.direction.cross(dirB));
        } else {
            J.block<3, 1>(0, j.axis) = sign * (wRb * j.direction);
        }
    }
}

void CompiledKinematics::pointJacobian(const AxisVector& q, double length, const int axes[3], Mat3& J, Vec3& tip) const {
    Lines lines;
    Frame w, t;
    cached(workpiece_, workpieceAxes_, workpieceCache_, q, w, &lines);
    const int workpieceLines = lines.count;
    cached(tool_, toolAxes_, toolCache_, q, t, &lines);
    const Vec3 dirB = t.R * machine_->toolDirection;
    const Vec3 tipB = t.t + length * dirB;
    const Mat3 wRb = w.R.transpose();
    tip = wRb * (tipB - w.t);
    J.setZero();
    for (int k = 0; k < lines.count; ++k) {
        const JointLine& j = lines.items[k];
        for (int c = 0; c < 3; ++c) {
            if (axes[c] != j.axis) continue;
            const double sign = k < workpieceLines ? -1.0 : 1.0;
            J.col(c) = sign * (wRb * (j.rotary ? j.direction.cross(tipB - j.point) : j.direction));
        }
    }
}

Frame CompiledKinematics::baseToWorkpiece(const AxisVector& q) const {
    Frame f;
    cached(workpiece_, workpieceAxes_, workpieceCache_, q, f, nullptr);
    return f;
}

Frame CompiledKinematics::baseToTool(const AxisVector& q) const {
    Frame f;
    cached(tool_, toolAxes_, toolCache_, q, f, nullptr);
    return f;
}

}  // namespace cnccomp::pp
