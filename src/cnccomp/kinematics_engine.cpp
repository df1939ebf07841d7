#include "cnccomp/kinematics_engine.hpp"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/xyz.hpp"

namespace cnccomp {

namespace {

std::atomic<uint64_t> modelCount{0};
uint64_t nextModelId() { return ++modelCount; }

bool isIdentity(const Mat3& R, const Vec3& t) { return R == Mat3::Identity() && t == Vec3::Zero(); }

/// R ← R · Rot(unit axis k, angle) given c = cos(angle), s = sin(angle): two columns change.
inline void rotateAboutUnit(Mat3& R, int k, double c, double s) {
    const int i = (k + 1) % 3, j = (k + 2) % 3;  // Rx: (y, z), Ry: (z, x), Rz: (x, y)
    const Vec3 a = R.col(i), b = R.col(j);
    R.col(i) = c * a + s * b;
    R.col(j) = c * b - s * a;
}

/// Eigen::AngleAxisd(θ, u).toRotationMatrix() given c = cos θ and s = sin θ: Eigen 3.4's operations in its order
/// (Eigen/src/Geometry/AngleAxis.h), so the same bits (Arithmetic::AsExactModel).
inline Mat3 angleAxisMatrix(const Vec3& u, double c, double s) {
    Mat3 res;
    const Vec3 sinAxis = s * u;
    const Vec3 cos1Axis = (1.0 - c) * u;
    double tmp = cos1Axis.x() * u.y();
    res(0, 1) = tmp - sinAxis.z();
    res(1, 0) = tmp + sinAxis.z();
    tmp = cos1Axis.x() * u.z();
    res(0, 2) = tmp + sinAxis.y();
    res(2, 0) = tmp - sinAxis.y();
    tmp = cos1Axis.y() * u.z();
    res(1, 2) = tmp - sinAxis.x();
    res(2, 1) = tmp + sinAxis.x();
    res.diagonal() = (cos1Axis.cwiseProduct(u)).array() + c;
    return res;
}

}  // namespace

namespace {
using xyz::toVec3;
using xyz::toXyz;
using xyz::Xyz;
}  // namespace

[[gnu::always_inline]] inline void KinematicsModel::rotateBack(const Op& op, double c, double s, Xyz& v) {
    switch (op.unit) {  // a coordinate axis k turns its plane (i, j) = ((k + 1) % 3, (k + 2) % 3)
        case 0: xyz::turnBack(c, s, v.y, v.z); return;
        case 1: xyz::turnBack(c, s, v.z, v.x); return;
        case 2: xyz::turnBack(c, s, v.x, v.y); return;
        default: {
            // Rodrigues with −θ: v c − s (u × v) + (1 − c)(u · v) u.
            const Vec3& u = op.dir;
            const Vec3 w = toVec3(v);
            v = toXyz(c * w - s * u.cross(w) + (1 - c) * u.dot(w) * u);
        }
    }
}

Pose KinematicsModel::componentError(const Op& op, const AxisVector& q) const {
    Vec6 e = Vec6::Zero();
    for (int k : op.components) {
        const DeviationDef& def = machine_->deviations[k];
        e[def.component] += def.basis.evaluate(q[op.axis], values_.data() + def.offset, op.modulo);
    }
    return errorTransform(e);
}

KinematicsModel::KinematicsModel(const MachineModel& machine, const DeviationSet* deviations, Arithmetic arithmetic)
    : machine_(&machine),
      exact_(arithmetic == Arithmetic::AsExactModel),
      id_(nextModelId()),
      values_(deviations ? deviations->values : Eigen::VectorXd::Zero(machine.parameterCount())) {
    if (deviations) deviations->requireMachine(machine);
    int slots = 0;
    compile(machine.workpiece, Side::Workpiece, workpiece_, slots);
    compile(machine.tool, Side::Tool, tool_, slots);
    rotarySlots_ = slots;
}

KinematicsData::KinematicsData(const KinematicsModel& model) { model.bind(*this); }

void KinematicsModel::rebind(KinematicsData& d) const {
    d = KinematicsData();
    d.model_ = id_;
    if (exact_) {
        d.angles_.assign(static_cast<size_t>(rotarySlots_), KinematicsData::AngleMemo());
        d.workpieceFrames_.entries.assign(kFrameMemo, KinematicsData::FrameEntry());
        d.toolFrames_.entries.assign(kFrameMemo, KinematicsData::FrameEntry());
        for (auto [trace, c] : {std::pair{&d.workpieceWalk_, &workpiece_}, std::pair{&d.toolWalk_, &tool_}}) {
            trace->key.assign(c->ops.size(), 0);
            trace->before.assign(c->ops.size(), Frame{});
        }
    }
}

KinematicsData::FrameEntry& KinematicsModel::memoFrame(KinematicsData& d, const ChainOps& c, KinematicsData::FrameMemo& memo,
                                                       const AxisVector& q) const {
    static_assert(kFrameMemo == 64);
    const auto holds = [&](const KinematicsData::FrameEntry& e) {
        bool hit = e.valid;
        for (size_t k = 0; k < c.axes.size() && hit; ++k) hit = e.key[k] == std::bit_cast<uint64_t>(q[c.axes[k]]);
        return hit;
    };
    if (KinematicsData::FrameEntry& e = memo.entries[memo.last]; holds(e)) return e;
    uint64_t h = 0;
    for (int a : c.axes) h = (h ^ std::bit_cast<uint64_t>(q[a])) * 0x9E3779B97F4A7C15ULL;
    memo.last = static_cast<size_t>(h >> 58);
    KinematicsData::FrameEntry& e = memo.entries[memo.last];
    if (!holds(e)) {
        evaluate(d, c, q, e.frame, nullptr);
        for (size_t k = 0; k < c.axes.size(); ++k) e.key[k] = std::bit_cast<uint64_t>(q[c.axes[k]]);
        e.valid = true;
        e.hasInverse = false;
    }
    return e;
}

// Inlined into the Fast path's evaluations (one call per rotary operation and evaluation, about a tenth of correct's
// kinematics time as a call: the results went through memory and the call was on the dependent chain).
[[gnu::always_inline]] inline void KinematicsModel::trig(Trig& t, double angle, double& c, double& s) {
    if (angle == t.asked) {  // the same angle again (a pose and its frame, a chain walked twice)
        c = t.askedC, s = t.askedS;
        return;
    }
    t.asked = angle;
    const double d = angle - t.last;
    if (std::fabs(d) <= 0.05) {
        // Near the last angle (consecutive evaluations: Newton steps, neighbouring blocks): angle addition with the
        // Taylor series of the difference, whose first omitted terms (d¹¹/11!, d¹²/12! < 1e-22) are far below a
        // rounding of the result.
        const double d2 = d * d;
        const double sd = d * (1 + d2 * (-1.0 / 6 + d2 * (1.0 / 120 + d2 * (-1.0 / 5040 + d2 * (1.0 / 362880)))));
        const double cd = 1 + d2 * (-0.5 + d2 * (1.0 / 24 + d2 * (-1.0 / 720 + d2 * (1.0 / 40320 + d2 * (-1.0 / 3628800)))));
        c = t.lastC * cd - t.lastS * sd;
        s = t.lastS * cd + t.lastC * sd;
    } else {
        c = std::cos(angle);
        s = std::sin(angle);
        t.last = angle, t.lastC = c, t.lastS = s;  // only exact evaluations become bases: no drift
    }
    t.askedC = c, t.askedS = s;
}

void KinematicsModel::exactTrig(KinematicsData& d, const Op& op, double angle, double& c, double& s) const {
    KinematicsData::AngleMemo& m = d.angles_[static_cast<size_t>(op.slot)];
    const uint64_t key = std::bit_cast<uint64_t>(angle);
    const int i = static_cast<int>((key * 0x9E3779B97F4A7C15ULL) >> 58);  // kAngleMemo = 64 entries
    static_assert(kAngleMemo == 64);
    if (m.key[i] != key) {
        m.key[i] = key;
        m.c[i] = std::cos(angle);  // as Eigen::AngleAxis::toRotationMatrix
        m.s[i] = std::sin(angle);
    }
    c = m.c[i], s = m.s[i];
}

[[gnu::always_inline]] inline void KinematicsModel::trigOf(KinematicsData& d, const Op& op, double angle, double& c,
                                                           double& s) const {
    if (exact_) exactTrig(d, op, angle, c, s);
    else trig(d.trig_[op.slot], angle, c, s);
}

void KinematicsModel::compile(const Chain& chain, Side side, ChainOps& c, int& slots) {
    c.side = side;
    std::vector<Op>& ops = c.ops;
    std::vector<int>& axes = c.axes;
    ops.clear();
    axes.clear();
    Frame pending;  // constant transforms not emitted yet
    auto flush = [&]() {
        if (isIdentity(pending.R, pending.t)) return;
        Op op;
        op.kind = OpKind::Constant;
        op.identityR = pending.R == Mat3::Identity();
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
                bool any = exact_;  // the exact model multiplies by a zero component error too
                for (int c = 0; c < def.size(); ++c) any = any || values_[def.offset + c] != 0.0;
                if (any) components.push_back(k);
            }
        }
        const Pose placed = l.placement * errorTransform(location);
        if (exact_) {  // one product per link, as the exact model (an identity too: its ±0 sums are the exact model's)
            Op op;
            op.kind = OpKind::Constant;
            op.R = placed.linear();
            op.t = placed.translation();
            ops.push_back(op);
        }
        // pending ← pending · placed (stays the identity with exact_: flush emits nothing)
        if (!exact_) {
            pending.t = pending.R * placed.translation() + pending.t;
            pending.R = pending.R * placed.linear();
        }
        if (l.kind == AxisKind::Fixed) continue;
        axes.push_back(l.axisIndex);
        flush();
        Op op;
        op.kind = l.kind == AxisKind::Linear ? OpKind::Linear : OpKind::Rotary;
        op.axis = l.axisIndex;
        op.dir = l.direction;
        op.modulo = l.modulo;
        if (op.kind == OpKind::Rotary) {
            if (slots >= kMaxAxes) throw ModelError(fmt::format("machine '{}' has more than {} rotary axes", machine_->name, kMaxAxes));
            op.slot = slots++;
        }
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
    // Affine chains (linear axes and constant transforms only: most tool chains of table-table machines).
    Affine& a = c.affine;
    a = Affine{};
    a.ok = !exact_;  // t0 + Σ colₖ qₖ sums in another order than the exact model
    for (const Op& op : ops) a.ok = a.ok && (op.kind == OpKind::Constant || op.kind == OpKind::Linear);
    if (!a.ok) return;
    for (const Op& op : ops) {
        if (op.kind == OpKind::Constant) {
            a.t0 += a.R * op.t;
            a.R = a.R * op.R;
        } else {
            a.axis[a.count] = op.axis;
            a.col[a.count] = a.R * op.dir;
            a.start[a.count] = a.t0;
            ++a.count;
        }
    }
    a.toolAxis = a.R * machine_->toolDirection;
}

template <bool Exact, class TrigOf>
void KinematicsModel::walk(const ChainOps& c, const AxisVector& q, Frame& f, JointFrames* lines, TrigOf&& trigOf,
                           KinematicsData::WalkTrace* trace) const {
    // Link by link as the model's equations read ([MultiTasking] eq. (7), (10)). Exact: from the identity, every
    // product done, rotations as Eigen's AngleAxis builds them; Fast: a leading constant transform is the frame so far,
    // identity rotations skipped, rotations about a coordinate axis turning two columns.
    auto it = c.ops.begin();
    const auto dependsOnAxis = [](const Op& op) { return op.kind != OpKind::Constant; };
    if (Exact && trace && trace->valid && !lines) {
        // Resumed: the frame before the first operation whose axis changed is the one the last walk had there (the
        // same operations on the same bits before it), so the walk goes on from there with the same arithmetic.
        it = c.ops.end();
        for (auto k = c.ops.begin(); k != c.ops.end(); ++k) {
            const size_t i = static_cast<size_t>(k - c.ops.begin());
            if (dependsOnAxis(*k) && trace->key[i] != std::bit_cast<uint64_t>(q[k->axis])) {
                it = k;
                break;
            }
        }
        f = it == c.ops.end() ? trace->last : trace->before[static_cast<size_t>(it - c.ops.begin())];
    } else if (!Exact && it != c.ops.end() && it->kind == OpKind::Constant) {
        f.R = it->R;
        f.t = it->t;
        ++it;
    } else {
        f.R.setIdentity();
        f.t.setZero();
    }
    for (; it != c.ops.end(); ++it) {
        const Op& op = *it;
        if (Exact && trace && dependsOnAxis(op)) {
            const size_t i = static_cast<size_t>(it - c.ops.begin());
            trace->key[i] = std::bit_cast<uint64_t>(q[op.axis]);
            trace->before[i] = f;
        }
        switch (op.kind) {
            case OpKind::Constant:
                f.t += f.R * op.t;
                if (Exact || !op.identityR) f.R = f.R * op.R;
                break;
            case OpKind::Linear:
                if (lines) lines->items[lines->count++] = {c.side, op.axis, false, f.R * op.dir, f.t};
                f.t += f.R * (op.dir * q[op.axis]);
                break;
            case OpKind::Rotary: {
                if (lines) lines->items[lines->count++] = {c.side, op.axis, true, f.R * op.dir, f.t};
                double cs, sn;
                trigOf(op, q[op.axis], cs, sn);
                if constexpr (Exact) {
                    f.R = f.R * angleAxisMatrix(op.dir, cs, sn);
                } else if (op.unit >= 0) {
                    rotateAboutUnit(f.R, op.unit, cs, sn);
                } else {
                    // Rodrigues: R(u, θ) = c I + s [u]× + (1 − c) u uᵀ.
                    const Vec3& u = op.dir;
                    const double c1 = 1 - cs;
                    Mat3 Ru;
                    Ru << cs + u.x() * u.x() * c1, u.x() * u.y() * c1 - u.z() * sn, u.x() * u.z() * c1 + u.y() * sn,
                        u.y() * u.x() * c1 + u.z() * sn, cs + u.y() * u.y() * c1, u.y() * u.z() * c1 - u.x() * sn,
                        u.z() * u.x() * c1 - u.y() * sn, u.z() * u.y() * c1 + u.x() * sn, cs + u.z() * u.z() * c1;
                    f.R = f.R * Ru;
                }
                break;
            }
            case OpKind::Component: {
                const Pose E = componentError(op, q);
                f.t += f.R * E.translation();
                f.R = f.R * E.linear();
                break;
            }
        }
    }
    if (Exact && trace) {
        trace->last = f;
        trace->valid = true;
    }
}

Frame KinematicsModel::chainFrame(Side side, const AxisVector& q, JointFrames* joints) const {
    Frame f;
    walk<true>(side == Side::Tool ? tool_ : workpiece_, q, f, joints, [](const Op&, double angle, double& cs, double& sn) {
        cs = std::cos(angle);  // as Eigen::AngleAxis::toRotationMatrix
        sn = std::sin(angle);
    });
    return f;
}

void KinematicsModel::evaluate(KinematicsData& d, const ChainOps& c, const AxisVector& q, Frame& f, JointFrames* lines) const {
    if (c.affine.ok) {
        const Affine& a = c.affine;
        f.R = a.R;
        f.t = a.t0;
        Vec3 moved = Vec3::Zero();  // by the axes before the current one
        for (int k = 0; k < a.count; ++k) {
            if (lines) lines->items[lines->count++] = {c.side, a.axis[k], false, a.col[k], a.start[k] + moved};
            moved += a.col[k] * q[a.axis[k]];
        }
        f.t += moved;
        return;
    }
    if (exact_)
        walk<true>(c, q, f, lines, [&](const Op& op, double angle, double& cs, double& sn) { exactTrig(d, op, angle, cs, sn); },
                   c.side == Side::Workpiece ? &d.workpieceWalk_ : &d.toolWalk_);
    else
        walk<false>(c, q, f, lines, [&](const Op& op, double angle, double& cs, double& sn) { trig(d.trig_[op.slot], angle, cs, sn); });
}

const KinematicsModel::ChainEntry& KinematicsModel::cached(KinematicsData& d, const ChainOps& c, ChainCache& cache,
                                                           const AxisVector& q, bool lines) const {
    if (c.affine.ok) {  // cheaper to evaluate than to look up
        ChainEntry& e = cache.entry[0];
        e.lines.count = 0;
        evaluate(d, c, q, e.frame, lines ? &e.lines : nullptr);
        e.valid = false;
        return e;
    }
    for (ChainEntry& e : cache.entry) {
        bool hit = e.valid && (e.hasLines || !lines);
        for (size_t k = 0; k < c.axes.size() && hit; ++k)  // exact_: the same bits (+0 and −0 are other commands)
            hit = exact_ ? std::bit_cast<uint64_t>(e.key[k]) == std::bit_cast<uint64_t>(q[c.axes[k]]) : e.key[k] == q[c.axes[k]];
        if (!hit) continue;
        cache.next = static_cast<int>(&e == &cache.entry[0]);  // keep the one just used
        return e;
    }
    ChainEntry& e = cache.entry[cache.next];
    cache.next ^= 1;
    e.lines.count = 0;
    evaluate(d, c, q, e.frame, lines ? &e.lines : nullptr);
    e.hasLines = lines;
    e.valid = true;
    for (size_t k = 0; k < c.axes.size(); ++k) e.key[k] = q[c.axes[k]];
    return e;
}

void KinematicsModel::toolPose(KinematicsData& d, const AxisVector& q, double length, Vec3& tip, Vec3& axis) const {
    bind(d);
    if (exact_) {  // toolPose(Kinematics, q, toolPoint(length)) in inverse_kinematics.cpp, operation for operation
        KinematicsData::FrameEntry& w = memoFrame(d, workpiece_, d.workpieceFrames_, q);
        const Frame& t = memoFrame(d, tool_, d.toolFrames_, q).frame;
        if (!w.hasInverse) {  // a grid's workpiece frames recur: each inverted once
            Pose bMw = Pose::Identity();
            bMw.linear() = w.frame.R;
            bMw.translation() = w.frame.t;
            w.inverse = bMw.inverse(Eigen::Isometry);
            w.hasInverse = true;
        }
        // wMt = bMw⁻¹ · bMt and wMt · p as Eigen's isometry products form them (the rotation blocks' product, the
        // rotation times the translation plus the translation), on 3×3 matrices instead of 4×4 transforms: the same
        // bits (TheExactModelIsTheLinkByLinkTranscriptionToTheBit compares with the isometries' products), about an
        // eighth less time per map point.
        const Mat3 wRb = w.inverse.linear();
        const Vec3 wtb = w.inverse.translation();
        const Mat3 R = wRb * t.R;
        const Vec3 tr = wRb * t.t + wtb;
        tip = R * Vec3(machine_->toolDirection * length + Vec3::Zero()) + tr;
        axis = R * machine_->toolDirection;
        return;
    }
    const Frame& w = cached(d, workpiece_, d.workpiece_, q, false).frame;
    const Frame& t = cached(d, tool_, d.tool_, q, false).frame;
    const Vec3 dirB = t.R * machine_->toolDirection;
    tip.noalias() = w.R.transpose() * (t.t + length * dirB - w.t);
    axis.noalias() = w.R.transpose() * dirB;
}

template <bool WithPoint, bool WithDirection>
void KinematicsModel::intoWorkpiece(KinematicsData& d, const AxisVector& q, Vec3& point, Vec3& direction) const {
    // w⁻¹ = op_N⁻¹ ⋯ op_1⁻¹ (op_1 nearest the base): op_1⁻¹ first. The point's and the direction's arithmetic are
    // independent: either alone gives the same bits as both. Walked on local copies (kept in registers: the references
    // could alias the model's operations).
    Xyz p = toXyz(point), dir = toXyz(direction);
    for (const Op& op : workpiece_.ops) {
        switch (op.kind) {
            case OpKind::Constant:
                if constexpr (WithPoint) p = {p.x - op.t[0], p.y - op.t[1], p.z - op.t[2]};
                if (!op.identityR) {
                    if constexpr (WithPoint) p = xyz::transposeTimes(op.R, p);
                    if constexpr (WithDirection) dir = xyz::transposeTimes(op.R, dir);
                }
                break;
            case OpKind::Linear:
                if constexpr (WithPoint) {
                    const double v = q[op.axis];
                    p = {p.x - op.dir[0] * v, p.y - op.dir[1] * v, p.z - op.dir[2] * v};
                }
                break;
            case OpKind::Rotary: {
                double c, sn;
                trigOf(d, op, q[op.axis], c, sn);
                if constexpr (WithPoint) rotateBack(op, c, sn, p);
                if constexpr (WithDirection) rotateBack(op, c, sn, dir);
                break;
            }
            case OpKind::Component: {
                const Pose E = componentError(op, q);
                if constexpr (WithPoint) p = toXyz(E.linear().transpose() * (toVec3(p) - E.translation()));
                if constexpr (WithDirection) dir = toXyz(E.linear().transpose() * toVec3(dir));
                break;
            }
        }
    }
    if constexpr (WithPoint) point = toVec3(p);
    if constexpr (WithDirection) direction = toVec3(dir);
}

void KinematicsModel::toolInBase(KinematicsData& d, const AxisVector& q, double length, Vec3& tip, Vec3& axis) const {
    bind(d);
    if (tool_.affine.ok) {  // the tool frame directly (no cache entry written)
        const Affine& a = tool_.affine;
        Vec3 t = a.t0;  // summed in a local (the reference could alias the model)
        for (int k = 0; k < a.count; ++k) t += a.col[k] * q[a.axis[k]];
        axis = a.toolAxis;
        tip = t + length * a.toolAxis;
    } else {
        const Frame& t = cached(d, tool_, d.tool_, q, false).frame;
        axis = t.R * machine_->toolDirection;
        tip = t.t + length * axis;
    }
}

void KinematicsModel::toolPoseOnce(KinematicsData& d, const AxisVector& q, double length, Vec3& tip, Vec3& axis) const {
    bind(d);
    if (workpiece_.affine.ok) {
        toolPose(d, q, length, tip, axis);
        return;
    }
    toolInBase(d, q, length, tip, axis);
    intoWorkpiece<true>(d, q, tip, axis);
}

Vec3 KinematicsModel::toolTipOnce(KinematicsData& d, const AxisVector& q, double length) const {
    bind(d);
    Vec3 tip, axis;
    if (workpiece_.affine.ok) {
        toolPose(d, q, length, tip, axis);
        return tip;
    }
    toolInBase(d, q, length, tip, axis);
    intoWorkpiece<true, false>(d, q, tip, axis);
    return tip;
}

Vec3 KinematicsModel::workpiecePointToBase(KinematicsData& d, const AxisVector& q, const Vec3& p) const {
    bind(d);
    if (workpiece_.affine.ok) {
        const Frame& w = cached(d, workpiece_, d.workpiece_, q, false).frame;
        return w.R * p + w.t;
    }
    // bMw = op_1 ⋯ op_N: op_N first.
    Xyz r = toXyz(p);
    for (auto it = workpiece_.ops.rbegin(); it != workpiece_.ops.rend(); ++it) {
        const Op& op = *it;
        switch (op.kind) {
            case OpKind::Constant:
                if (!op.identityR) r = xyz::times(op.R, r);
                r = {r.x + op.t[0], r.y + op.t[1], r.z + op.t[2]};
                break;
            case OpKind::Linear: {
                const double v = q[op.axis];
                r = {r.x + op.dir[0] * v, r.y + op.dir[1] * v, r.z + op.dir[2] * v};
                break;
            }
            case OpKind::Rotary: {
                double c, sn;
                trigOf(d, op, q[op.axis], c, sn);
                rotateBack(op, c, -sn, r);  // Rot(θ) = Rot(−θ)ᵀ
                break;
            }
            case OpKind::Component: {
                const Pose E = componentError(op, q);
                r = toXyz(E.linear() * toVec3(r) + E.translation());
                break;
            }
        }
    }
    return toVec3(r);
}

Vec3 KinematicsModel::toolAxisOnce(KinematicsData& d, const AxisVector& q) const {
    bind(d);
    if (workpiece_.affine.ok) {
        Vec3 tip, axis;
        toolPose(d, q, 0.0, tip, axis);
        return axis;
    }
    Vec3 axis = tool_.affine.ok ? tool_.affine.toolAxis : Vec3(cached(d, tool_, d.tool_, q, false).frame.R * machine_->toolDirection);
    Vec3 unused;
    intoWorkpiece<false>(d, q, unused, axis);
    return axis;
}

void KinematicsModel::takeAngles(KinematicsData& d, const KinematicsModel& other, const KinematicsData& from) const {
    bind(d);
    if (exact_ || other.exact_ || machine_ != other.machine_ || from.model_ != other.id_) return;
    std::copy(from.trig_, from.trig_ + rotarySlots_, d.trig_);
}

Vec3 KinematicsModel::toolTip(KinematicsData& d, const AxisVector& q, double length) const {
    Vec3 tip, axis;
    toolPose(d, q, length, tip, axis);
    return tip;
}

void KinematicsModel::jacobian(KinematicsData& d, const AxisVector& q, double length, PoseJacobian& J, Vec3& tip, Vec3& axis) const {
    bind(d);
    const ChainEntry& we = cached(d, workpiece_, d.workpiece_, q, true);
    const ChainEntry& te = cached(d, tool_, d.tool_, q, true);
    const Frame &w = we.frame, &t = te.frame;
    const Vec3 dirB = t.R * machine_->toolDirection;
    const Vec3 tipB = t.t + length * dirB;
    const Mat3 wRb = w.R.transpose();
    tip = wRb * (tipB - w.t);
    axis = wRb * dirB;
    J.setZero(6, q.size());
    // Tool-side motion moves the tool; workpiece-side motion moves the workpiece, i.e. the tool relative to it the
    // other way (as cnccomp::toolPoseJacobian; component errors' own slopes are neglected).
    for (const ChainEntry* e : {&we, &te}) {
        const double sign = e == &we ? -1.0 : 1.0;
        for (int k = 0; k < e->lines.count; ++k) {
            const JointFrame& j = e->lines.items[k];
            if (j.rotary) {
                J.block<3, 1>(0, j.axis) = sign * (wRb * j.direction.cross(tipB - j.point));
                J.block<3, 1>(3, j.axis) = sign * (wRb * j.direction.cross(dirB));
            } else {
                J.block<3, 1>(0, j.axis) = sign * (wRb * j.direction);
            }
        }
    }
}

void KinematicsModel::pointJacobian(KinematicsData& d, const AxisVector& q, double length, const int axes[3], Mat3& J, Vec3& tip) const {
    bind(d);
    // Joint lines only of the chains that hold one of the axes.
    auto holds = [&](const ChainOps& c) {
        for (int a : c.axes)
            if (a == axes[0] || a == axes[1] || a == axes[2]) return true;
        return false;
    };
    const ChainEntry& we = cached(d, workpiece_, d.workpiece_, q, holds(workpiece_));
    const ChainEntry& te = cached(d, tool_, d.tool_, q, holds(tool_));
    const Frame &w = we.frame, &t = te.frame;
    const Vec3 dirB = t.R * machine_->toolDirection;
    const Vec3 tipB = t.t + length * dirB;
    const Mat3 wRb = w.R.transpose();
    tip = wRb * (tipB - w.t);
    J.setZero();
    for (const ChainEntry* e : {&we, &te}) {
        const double sign = e == &we ? -1.0 : 1.0;
        for (int k = 0; k < e->lines.count; ++k) {
            const JointFrame& j = e->lines.items[k];
            for (int c = 0; c < 3; ++c)
                if (axes[c] == j.axis) J.col(c) = sign * (wRb * (j.rotary ? j.direction.cross(tipB - j.point) : j.direction));
        }
    }
}

Frame KinematicsModel::baseToWorkpiece(KinematicsData& d, const AxisVector& q) const {
    bind(d);
    return cached(d, workpiece_, d.workpiece_, q, false).frame;
}

Frame KinematicsModel::baseToTool(KinematicsData& d, const AxisVector& q) const {
    bind(d);
    return cached(d, tool_, d.tool_, q, false).frame;
}

}  // namespace cnccomp
