#include "postproc/midpoint_bound.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/LU>  // Matrix3d::inverse

namespace cnccomp::postproc {

namespace {

/// The workpiece chain as a product of exponentials: W(θ) = Πᵢ [T(rᵢ) Rot(ωᵢ, θᵢ) T(−rᵢ)] · W(0), the joint lines
/// (ωᵢ, rᵢ) at θ = 0, rᵢ the point of the line nearest the origin.
struct Exponentials {
    int count = 0;
    int axis[kMaxAxes] = {};
    Vec3 omega[kMaxAxes], r[kMaxAxes];
    Frame atZero;

    bool read(const KinematicsModel& model, int n) {
        JointFrames lines;
        atZero = model.chainFrame(Side::Workpiece, AxisVector::Zero(n), &lines);
        count = lines.count;
        for (int i = 0; i < count; ++i) {
            const JointFrame& j = lines.items[i];
            if (!j.rotary || std::fabs(j.direction.norm() - 1.0) > 1e-12) return false;
            axis[i] = j.axis;
            omega[i] = j.direction;
            r[i] = j.point - j.point.dot(omega[i]) * omega[i];
        }
        return true;
    }
    Frame at(const AxisVector& q) const {
        // f = E₁ E₂ ⋯ E_k W(0), Eᵢ x = R(ωᵢ, θᵢ)(x − rᵢ) + rᵢ.
        Frame f = atZero;
        for (int i = count - 1; i >= 0; --i) {
            const Mat3 R = Eigen::AngleAxisd(q[axis[i]], omega[i]).toRotationMatrix();
            f.t = R * (f.t - r[i]) + r[i];
            f.R = R * f.R;
        }
        return f;
    }
    /// The translations of the constants between the rotations: r₁, r₂ − r₁, …, t(W(0)) − r_k.
    Vec3 constant(int i) const {
        if (count == 0) return atZero.t;
        if (i == 0) return r[0];
        if (i < count) return r[i] - r[i - 1];
        return atZero.t - r[count - 1];
    }
};

}  // namespace

MidpointBound::MidpointBound(const KinematicsModel& nominal, const KinematicsModel& actual, const TcpModel& tcp,
                             bool locationOnly) {
    if (!locationOnly || !tcp.supported() || !tcp.fixedSlides()) return;
    const MachineModel& m = nominal.machine();
    const int n = m.axisCount();
    tcp_ = &tcp;
    for (int k = 0; k < 3; ++k) lin_[k] = tcp.linearAxis(k);

    // The workpiece chain: rotary axes only, the same in both models.
    Exponentials W, Wa;
    if (!W.read(nominal, n) || !Wa.read(actual, n) || W.count != Wa.count || W.count + 3 != n) return;
    for (int i = 0; i < W.count; ++i)
        if (W.axis[i] != Wa.axis[i]) return;
    rotaryCount_ = W.count;
    for (int i = 0; i < W.count; ++i) rotary_[i] = W.axis[i];
    // The decomposition reproduces both chains (a check of the joint lines' conventions).
    for (int s = 0; s < 4; ++s) {
        AxisVector q = AxisVector::Zero(n);
        for (int i = 0; i < W.count; ++i) q[W.axis[i]] = std::sin(1.7 * s + 0.9 * i + 0.3) * 3.0;
        for (const auto* e : {&W, &Wa}) {
            const Frame f = e->at(q), g = (e == &W ? nominal : actual).chainFrame(Side::Workpiece, q);
            if ((f.R - g.R).norm() > 1e-12 || (f.t - g.t).norm() > 1e-12 * (1.0 + g.t.norm())) return;
        }
    }
    // εR, εt, CW (see the header): each tilted axis' turn Q (‖Q − I‖ = |ω̃ − ω|) enters the constants on both sides.
    epsR_ = (Wa.atZero.R - W.atZero.R).norm();
    for (int i = 0; i < W.count; ++i) epsR_ += 2.0 * (Wa.omega[i] - W.omega[i]).norm();
    epsT_ = 0;
    cw_ = cwActual_ = 0;
    for (int i = 0; i <= W.count; ++i) {
        const Vec3 c = W.constant(i), ca = Wa.constant(i);
        const double tilt = i == 0 ? 0.0 : (Wa.omega[i - 1] - W.omega[i - 1]).norm();  // Qᵢᵀ before the translation
        epsT_ += tilt * ca.norm() + (ca - c).norm();
        cw_ += c.norm();
        cwActual_ += ca.norm();
    }
    tau_ = epsR_ * cw_ + epsT_;

    // The tool chain: the three slides, affine (tool point T0 + S x + L u in the bed).
    JointFrames jt, jta;
    nominal.chainFrame(Side::Tool, AxisVector::Zero(n), &jt);
    actual.chainFrame(Side::Tool, AxisVector::Zero(n), &jta);
    if (jt.count != 3 || jta.count != 3) return;
    for (int k = 0; k < 3; ++k)
        if (jt.items[k].rotary || jta.items[k].rotary ||
            std::find(lin_, lin_ + 3, jt.items[k].axis) == lin_ + 3)
            return;
    const AxisVector zero = m.fromController(AxisVector::Zero(n));
    for (int k = 0; k < 3; ++k) zeroLin_[k] = zero[lin_[k]];
    Mat3 S, Sa;
    for (const KinematicsModel* model : {&nominal, &actual}) {
        KinematicsData d = model->createData();
        Vec3 t0, u, tip, axis;
        model->toolInBase(d, AxisVector::Zero(n), 0.0, t0, u);
        Mat3& cols = model == &nominal ? S : Sa;
        for (int k = 0; k < 3; ++k) {
            AxisVector q = AxisVector::Zero(n);
            q[lin_[k]] = 1.0;
            model->toolInBase(d, q, 0.0, tip, axis);
            cols.col(k) = tip - t0;
        }
        (model == &nominal ? t0_ : t0Actual_) = t0;
        (model == &nominal ? u_ : uActual_) = u;
    }
    if (std::fabs(S.determinant()) < 1e-6) return;
    const Mat3 Sinv = S.inverse();
    // The controller's inverse uses these slides (its D⁻¹ is S⁻¹): the nominal inverse is exact.
    if ((tcp.slidesInverse() * S - Mat3::Identity()).norm() > 1e-12) return;
    const Mat3 K = Sa * Sinv - Mat3::Identity();
    k_ = K.norm();
    slidesActual_ = Sa.norm();
    w0_ = (t0Actual_ - t0_) - K * t0_;
    wL_ = uActual_ - u_;
    wLc_ = K * u_;
    // The TCP world frame is the workpiece frame turned and moved (TcpModel: p = R0ᵀ (x − t0)): |p| = |x − t0|.
    Mat3 R0;
    for (int k = 0; k < 3; ++k) R0.col(k) = tcp.axisToWorld(Vec3::Unit(k));
    if ((R0.transpose() * R0 - Mat3::Identity()).norm() > 1e-12) return;
    worldOrigin_ = -R0 * tcp.pointFromWorld(Vec3::Zero());
    usable_ = std::isfinite(epsR_ + epsT_ + cw_ + cwActual_ + k_ + slidesActual_ + worldOrigin_.norm() + w0_.norm());
}

double MidpointBound::endBound(double tipError, const AxisVector& c, double toolLength, double solveTolerance) const {
    // The solve's last step (≤ solveTolerance per slide, solveTolerance / 100 rad per rotary axis) after its residual
    // was taken: the slides move the tool point by ‖S̃‖ per mm, a rotary axis by at most the point's distance from the
    // bed origin plus the chain's constants (|z| + 2 C̃W).
    Vec3 x;
    for (int k = 0; k < 3; ++k) x[k] = c[lin_[k]] + zeroLin_[k];
    const double step = std::sqrt(3.0) * solveTolerance;
    const double z = t0Actual_.norm() + slidesActual_ * (x.norm() + step) + std::fabs(toolLength) * uActual_.norm();
    return tipError + slidesActual_ * step + (z + 2.0 * cwActual_) * rotaryCount_ * 1e-2 * solveTolerance;
}

void MidpointBound::parts(double toolLength, double controlLength, const AxisVector& outStart, const AxisVector& end,
                          const AxisVector& nomStart, const AxisVector& nomEnd, const AxisVector& prevEnd,
                          double& start, double& curvature) const {
    const Vec3 s(outStart[lin_[0]], outStart[lin_[1]], outStart[lin_[2]]);
    const Vec3 e(end[lin_[0]], end[lin_[1]], end[lin_[2]]);
    const Vec3 pe(prevEnd[lin_[0]], prevEnd[lin_[1]], prevEnd[lin_[2]]);
    const double s2 = (s - worldOrigin_).squaredNorm();
    const double P = std::sqrt(std::max(s2, (e - worldOrigin_).squaredNorm()));  // over the move
    const double P0 = std::sqrt(std::max(s2, (pe - worldOrigin_).squaredNorm()));  // unrounded end to written start
    double om = 0, omN = 0, d0 = 0, d1 = 0, dd = 0, turn = 0;
    for (int k = 0; k < rotaryCount_; ++k) {
        const int a = rotary_[k];
        const double e0 = outStart[a] - nomStart[a], e1 = end[a] - nomEnd[a];
        om += std::fabs(end[a] - outStart[a]);
        omN += std::fabs(nomEnd[a] - nomStart[a]);
        d0 += std::fabs(e0), d1 += std::fabs(e1), dd += std::fabs(e1 - e0);
        turn += std::fabs(outStart[a] - prevEnd[a]);
    }
    const Vec3 w = w0_ + toolLength * wL_ - controlLength * wLc_;
    const double wn = w.norm(), v = (e - s).norm();
    const double dl = std::fabs(toolLength - controlLength) * u_.norm();
    const double omBar = std::max(om, omN), om2 = om * om;
    curvature = (epsR_ * (4 * om2 * P + 4 * om * v) + 4 * om2 * tau_ + k_ * (4 * om2 * (P + cw_) + 4 * om * v) +
                 om2 * wn + dl * (epsR_ * om2 + omBar * omBar * std::max(d0, d1) + 2 * omBar * dd)) /
                8;
    const double v0 = (w + (toolLength - controlLength) * u_).norm();
    const double lever = 2 * epsR_ * P0 + 2 * tau_ + 2 * k_ * (P0 + cw_) + v0;
    start = (1 + k_) * (s - pe).norm() + turn * lever;
}

double MidpointBound::curvatureTerm(double toolLength, double controlLength, const AxisVector& outStart,
                                    const AxisVector& end, const AxisVector& nomStart, const AxisVector& nomEnd) const {
    double start, curvature;
    parts(toolLength, controlLength, outStart, end, nomStart, nomEnd, outStart, start, curvature);
    return curvature;
}

double MidpointBound::midpoint(double toolLength, double controlLength, const AxisVector& outStart,
                               const AxisVector& end, const AxisVector& nomStart, const AxisVector& nomEnd,
                               const AxisVector& prevEnd, double prevEndBound, double endBound) const {
    // d(0): the previous end's deviation, moved from its unrounded end to the written start.
    double start, curvature;
    parts(toolLength, controlLength, outStart, end, nomStart, nomEnd, prevEnd, start, curvature);
    const double u = 0.5 * (prevEndBound + start + endBound) + curvature;
    return u * (1 + 1e-6) + 1e-9;
}

}  // namespace cnccomp::postproc
