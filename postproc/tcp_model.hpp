#pragma once
// The controller's nominal tool-centre-point (TCP) kinematics: how it turns the positions of a TCP-mode program
// (Fanuc G43.4 / G43.5, Sinumerik TRAORI, LinuxCNC's switchable xyzac/xyzbc-trt-kins) into its machine coordinates.
//
// A TCP program gives the controlled point of the tool — the point at the controller's tool length Lc along the tool
// axis (the active G43 / D offset, 0 without one) — in the controller's world frame, and the orientation as rotary
// angles (which are the rotary machine coordinates) or as a vector (I J K, A3 B3 C3) pointing from the tip towards the
// spindle. The world frame is the workpiece (table) frame as it lies at the controller's machine zero: at all rotary
// axes 0 the world coordinates of the controlled point equal the machine coordinates of the linear axes minus Lc
// along the tool (LinuxCNC: trtfuncs.c with the rot-point pins at machine zero; the world is the one identity
// kinematics shows at A = C = 0). Formally, with q = c + machineZero the model commands of machine coordinates c and
// qz = machineZero the model commands of machine zero:
//   world point  = bRw(qz) · p_w + bTw(qz) − gauge(qz),   world vector = bRw(qz) · v_w,
// p_w, v_w in the model's workpiece frame, gauge(qz) = where the tool frame origin (tool length 0) is in the bed.
// Program-space vectors use the machine's axis layout: the X, Y, Z slots hold the world x, y, z of the controlled
// point, the rotary slots the rotary angles (rad).
#include "cnccomp/kinematics_engine.hpp"

namespace cnccomp::postproc {

class TcpModel {
public:
    /// `data`: the workspace of `nominal` the constructor evaluates with (the machine zero's frames).
    TcpModel(const KinematicsModel& nominal, KinematicsData& data);

    /// False when the machine has no linear X, Y and Z axes (TCP programs cannot be read for it); why() says so.
    bool supported() const { return supported_; }
    const char* why() const { return why_; }

    // The evaluations below use `d`, a workspace of the nominal model given to the constructor.

    /// World controlled point (tool length `length`) and world tool axis (spindle → tip) at machine coordinates c.
    void forward(KinematicsData& d, const AxisVector& c, double length, Vec3& point, Vec3& axis) const;
    /// Program-space position of machine coordinates c (angles mode and the point of vector mode).
    void toProgram(KinematicsData& d, const AxisVector& c, double length, AxisVector& p) const;
    /// Machine coordinates of program-space p in angles mode: rotary axes at p's angles, linear axes solved
    /// (exact: with the rotary axes fixed the nominal point is affine in the linear axes). `c` may alias nothing.
    /// With `tip` and `axis`: the nominal point at `length` and tool axis there (model workpiece frame) when the solve
    /// gives them on the way (returns true), else false and they are not set.
    bool toJoints(KinematicsData& d, const AxisVector& p, double length, AxisVector& c, Vec3* tip = nullptr, Vec3* axis = nullptr) const;
    /// World tool axis (spindle → tip) in the world frame → model workpiece frame, and back.
    Vec3 axisToWorld(const Vec3& axisW) const { return R0_ * axisW; }
    Vec3 axisFromWorld(const Vec3& axisWorld) const { return R0_.transpose() * axisWorld; }
    Vec3 pointFromWorld(const Vec3& pWorld) const { return R0_.transpose() * (pWorld - t0_); }
    int linearAxis(int k) const { return lin_[k]; }
    /// The slides move along fixed bed directions: the inverse is exact (one linear solve with slidesInverse()).
    bool fixedSlides() const { return fixedSlides_; }
    const Mat3& slidesInverse() const { return slidesInverse_; }
    const int* linearAxes() const { return lin_; }

private:
    /// Model commands of machine coordinates c: c itself when machine zero is the model's zero, else c + zero_ in
    /// `scratch`.
    const AxisVector& model(const AxisVector& c, AxisVector& scratch) const {
        if (zeroIsZero_) return c;
        scratch = c + zero_;
        return scratch;
    }
    const KinematicsModel& nominal_;
    AxisVector zero_;  ///< model commands of the controller's machine zero
    bool zeroIsZero_ = true;
    Mat3 R0_ = Mat3::Identity();
    Vec3 t0_ = Vec3::Zero();
    int lin_[3] = {-1, -1, -1};
    /// The X, Y, Z slides move along fixed bed directions (no rotary axis before them in their chains): the point's
    /// derivatives by them are R0 · wRbᵀ · D with D constant, and the linear solve is D⁻¹ · wRb · R0ᵀ (no Jacobian).
    bool fixedSlides_ = false;
    Mat3 slidesInverse_ = Mat3::Identity();  ///< D⁻¹, D's columns ± the slides' bed directions (− workpiece side)
    bool supported_ = false;
    const char* why_ = "";
};

}  // namespace cnccomp::postproc
