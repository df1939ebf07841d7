#include "postproc/tcp_model.hpp"

#include <Eigen/LU>  // Matrix3d::inverse

namespace cnccomp::postproc {

TcpModel::TcpModel(const KinematicsModel& nominal, KinematicsData& data) : nominal_(nominal) {
    const MachineModel& m = nominal.machine();
    const int n = m.axisCount();
    zero_ = m.fromController(AxisVector::Zero(n));
    zeroIsZero_ = (zero_.array() == 0.0).all();
    const char names[3] = {'X', 'Y', 'Z'};
    supported_ = true;
    for (int k = 0; k < 3; ++k) {
        const int a = m.axisIndex(std::string(1, names[k]));
        if (a < 0 || m.axisLink(a).kind != AxisKind::Linear) {
            supported_ = false;
            why_ = "tool-tip programming needs linear X, Y and Z axes";
        }
        lin_[k] = a;
    }
    if (supported_) {
        // Slides with a fixed bed direction: no rotary link before them in their chain.
        Mat3 D;
        fixedSlides_ = true;
        for (int k = 0; k < 3; ++k) {
            bool rotaryBefore = false, found = false;
            for (const Chain* chain : {&m.workpiece, &m.tool}) {
                bool rotary = false;
                for (const Link& l : chain->links) {
                    if (l.axisIndex == lin_[k]) {
                        found = true;
                        rotaryBefore = rotary;
                        D.col(k) = (chain == &m.workpiece ? -1.0 : 1.0) * m.nominalDirection(lin_[k]);
                        break;
                    }
                    rotary = rotary || l.kind == AxisKind::Rotary;
                }
                if (found) break;
            }
            fixedSlides_ = fixedSlides_ && found && !rotaryBefore;
        }
        fixedSlides_ = fixedSlides_ && std::fabs(D.determinant()) > 1e-6;
        if (fixedSlides_) slidesInverse_ = D.inverse();
    }
    const Frame w = nominal.baseToWorkpiece(data, zero_);
    const Frame t = nominal.baseToTool(data, zero_);
    R0_ = w.R;
    t0_ = w.t - t.t;
}

void TcpModel::forward(KinematicsData& d, const AxisVector& c, double length, Vec3& point, Vec3& axis) const {
    AxisVector scratch;
    const AxisVector& q = model(c, scratch);
    Vec3 pw, aw;
    nominal_.toolPoseOnce(d, q, length, pw, aw);
    point = R0_ * pw + t0_;
    axis = R0_ * aw;
}

void TcpModel::toProgram(KinematicsData& d, const AxisVector& c, double length, AxisVector& p) const {
    AxisVector scratch;
    const AxisVector& q = model(c, scratch);
    const Vec3 point = R0_ * nominal_.toolTipOnce(d, q, length) + t0_;  // forward's point, without the axis
    p = c;
    for (int k = 0; k < 3; ++k) p[lin_[k]] = point[k];
}

bool TcpModel::toJoints(KinematicsData& d, const AxisVector& p, double length, AxisVector& c, Vec3* tipOut, Vec3* axisOut) const {
    c = p;  // rotary angles as programmed; linear axes start at the world coordinates
    AxisVector scratch;
    const AxisVector& q = model(c, scratch);  // (may be c itself: read before c changes below)
    const Vec3 want(p[lin_[0]], p[lin_[1]], p[lin_[2]]);
    if (fixedSlides_) {
        // The world point is R0 · bMw⁻¹ · tipB + t0 with tipB − bTw affine in the slides (tipB − bTw moves by D · dq):
        // it equals `want` when D · dq = bMw · pointFromWorld(want) − tipB — one walk of the workpiece chain, no
        // Jacobian.
        const bool pose = tipOut && axisOut;
        const Vec3 wantW = pointFromWorld(want);
        const Vec3 wantB = nominal_.workpiecePointToBase(d, q, wantW);
        Vec3 tipB, axisB;
        nominal_.toolInBase(d, q, length, tipB, axisB);
        const Vec3 dq = slidesInverse_ * (wantB - tipB);
        if (pose) *axisOut = nominal_.toolAxisOnce(d, q);  // the slides do not turn the tool (q read before c changes)
        for (int k = 0; k < 3; ++k) c[lin_[k]] += dq[k];
        if (!pose) return false;
        *tipOut = wantW;  // where the slides just put it (the point is affine in them)
        return true;
    }
    Mat3 J;
    Vec3 tip;
    nominal_.pointJacobian(d, q, length, lin_, J, tip);
    const Mat3 A = R0_ * J;
    const Vec3 have = R0_ * tip + t0_;
    const Vec3 dq = A.inverse() * (want - have);  // 3 x 3, well conditioned (the slides are orthogonal nominally)
    for (int k = 0; k < 3; ++k) c[lin_[k]] += dq[k];
    return false;
}

}  // namespace cnccomp::postproc
