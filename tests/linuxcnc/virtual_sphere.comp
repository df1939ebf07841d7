component virtual_sphere "Test harness of cnccomp: a touch probe and a calibration sphere on an erroneous A/C table-table machine";
description
"""
A realtime HAL component of cnccomp's LinuxCNC tests (tests/linuxcnc/virtual_sphere.comp; not part of the product).
Every servo cycle it reads the joint positions the drives are at (net joint.N.motor-pos-cmd to x y z a c: after
LinuxCNC's kinematics, comp tables and backlash, i.e. where the real machine's axes are), computes the centre of the
stylus ball relative to the rotary table with a forward model of an ERRONEOUS table-table A/C machine (the truth: the
location errors of the A and C axes) and raises probe (net it to motion.probe-input) while the ball touches the
sphere: |ball centre - sphere centre| <= sphere-radius + ball-radius - trigger-travel.

The machine (cnccomp's samples/machines/table-table-ac.xml): workpiece chain bed -> A (about +X) -> C (about +Z) ->
table, origin at the intersection of the nominal A and C axes; tool chain bed -> Y -> X -> Z -> spindle, the slides
along +X +Y +Z, no machine-zero offsets, tool along -Z. Direction of the rotations as LinuxCNC's xyzac-trt-kins
(src/emc/kinematics/trtfuncs.c, 2.9, xyzacKinematicsInverse): the joints of a workpiece point p are Rx(A) Rz(C) p, i.e.
the table turns right-handed about +X by A and about +Z by C.

The deviations (ISO 230-1:2012 location errors of axes of rotation, ISO 230-7; right-hand rotations about +X +Y +Z,
translations along them; first-order definitions, composed here with exact rotations):
  A axis line, in the bed frame: through (0, ey0a, ez0a), direction Rz(ec0a) Ry(eb0a) (1 0 0) (ey0a, ez0a: its
  position at x = 0; eb0a, ec0a: its orientation about Y and about Z).
  The cradle frame (what A carries, at A = 0): origin on the A line at (0, ey0a, ez0a), axes Rz(ec0a) Ry(eb0a).
  C axis line, in the cradle frame (ISO's location of an axis carried by another axis of rotation, relative to the
  carrier at its zero; the machine description: "POPPE of C, relative to the A cradle"): through (ex0c, ey0c, 0),
  direction Rx(ea0c) Ry(eb0c) (0 0 1).
  The table frame: on the C line at the cradle's z = 0, axes Rx(ea0c) Ry(eb0c) of the cradle frame, turned by C.
So a point p of the table is in the bed frame at
  P_A + R_A Rx(a) (t_C + R_C Rz(c) p),  P_A = (0, ey0a, ez0a), R_A = Rz(ec0a) Ry(eb0a), t_C = (ex0c, ey0c, 0),
  R_C = Rx(ea0c) Ry(eb0c),
and the ball centre (x, y, z - tool-length) of the bed frame is in the table frame at
  Rz(-c) R_C^T (Rx(-a) R_A^T (b - P_A) - t_C).
Written for the harness from these definitions, not from cnccomp's model: the independent oracle of the sphere
probing loop (tests/linuxcnc/test_linuxcnc_probe.cpp).

Parameters (setp): tool-length (mm, spindle reference point to the ball centre along -Z), ball-radius,
sphere-radius (mm), sphere-x/-y/-z (the sphere centre in the table frame, mm), trigger-travel (mm: the ball must go
this far into contact before the probe triggers, a probe's pre-travel), ey0a ez0a ex0c ey0c (mm), eb0a ec0a ea0c eb0c
(rad).
Pins: x y z (mm) a c (deg) in; probe (bit) out; gap out (mm: distance between the ball's and the sphere's surfaces,
negative inside); ball-x/-y/-z out (the ball centre in the table frame, mm); touches out (rising edges of probe).
""";
pin in float x "X joint position (mm): net joint.N.motor-pos-cmd of X";
pin in float y "Y joint position (mm)";
pin in float z "Z joint position (mm)";
pin in float a "A joint position (deg)";
pin in float c "C joint position (deg)";
pin out bit probe "the ball touches the sphere: net to motion.probe-input";
pin out float gap "distance between the surfaces of ball and sphere (mm; negative: inside)";
pin out float ball_x "ball centre in the table frame (mm)";
pin out float ball_y;
pin out float ball_z;
pin out s32 touches "rising edges of probe";
param rw float tool_length = 0 "spindle reference point to ball centre along -Z (mm)";
param rw float ball_radius = 1.5 "stylus ball radius (mm)";
param rw float sphere_radius = 12.5 "calibration sphere radius (mm)";
param rw float sphere_x = 0 "sphere centre in the table frame (mm)";
param rw float sphere_y = 0;
param rw float sphere_z = 0;
param rw float trigger_travel = 0 "pre-travel of the probe (mm)";
param rw float ey0a = 0 "A axis line: Y position (mm)";
param rw float ez0a = 0 "A axis line: Z position (mm)";
param rw float eb0a = 0 "A axis line: orientation about Y (rad)";
param rw float ec0a = 0 "A axis line: orientation about Z (rad)";
param rw float ex0c = 0 "C axis line in the cradle frame: X position (mm)";
param rw float ey0c = 0 "C axis line in the cradle frame: Y position (mm)";
param rw float ea0c = 0 "C axis line in the cradle frame: orientation about X (rad)";
param rw float eb0c = 0 "C axis line in the cradle frame: orientation about Y (rad)";
function _;
option singleton yes;
license "GPL";
author "cnccomp tests";
;;
#include "rtapi_math.h"

/* v := R(axis, angle) v, right-handed about +X (0), +Y (1) or +Z (2). */
static void vs_rotate(double v[3], int axis, double angle) {
    const double s = sin(angle), k = cos(angle);
    const int i = (axis + 1) % 3, j = (axis + 2) % 3; /* X: (y, z); Y: (z, x); Z: (x, y) */
    const double vi = v[i], vj = v[j];
    v[i] = k * vi - s * vj;
    v[j] = s * vi + k * vj;
}

FUNCTION(_) {
    const double deg = M_PI / 180.0;
    double v[3], d[3], dist;
    int on;
    v[0] = x;
    v[1] = y - ey0a;
    v[2] = z - tool_length - ez0a;
    /* R_A^T = Ry(-eb0a) Rz(-ec0a) */
    vs_rotate(v, 2, -ec0a);
    vs_rotate(v, 1, -eb0a);
    vs_rotate(v, 0, -a * deg);
    v[0] -= ex0c;
    v[1] -= ey0c;
    /* R_C^T = Ry(-eb0c) Rx(-ea0c) */
    vs_rotate(v, 0, -ea0c);
    vs_rotate(v, 1, -eb0c);
    vs_rotate(v, 2, -c * deg);
    ball_x = v[0];
    ball_y = v[1];
    ball_z = v[2];
    d[0] = v[0] - sphere_x;
    d[1] = v[1] - sphere_y;
    d[2] = v[2] - sphere_z;
    dist = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    gap = dist - sphere_radius - ball_radius;
    on = gap <= -trigger_travel;
    if (on && !probe) touches++;
    probe = on;
}
