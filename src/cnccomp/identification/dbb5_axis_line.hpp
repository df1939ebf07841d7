#pragma once
// The average line of a rotary axis from DBB5 rotary runs at two positions along the axis — S. Ibaraki, Y. Kakino,
// T. Akai, N. Takayama, I. Yamaji, K. Ogawa, "Identification of motion error sources on five-axis machine tools by
// ball-bar measurements (1st report): classification of motion error components and development of the modified
// ball bar device (DBB5)", sections 4.2.1 (C axis, eq. (1)–(3)), 4.2.3 (ISO 10791-6 XYC test, eq. (4)–(5)) and 4.3
// (B axis, eq. (6)–(7)).
//
// A rotary run turns one axis with the table ball on it while the spindle ball keeps a fixed bed-frame direction u
// from the table ball. The mean radial error r of the run (ISO 230-4, the constant term of the full circle an arc
// belongs to) is r = −u·c, c the shift of the axis line at the ball's position along the axis (first order), so the
// centre shift along a machine axis e is c_e = −r/(u·e). Two positions s1 < s2 along the axis give the line:
//   lean_e = (c_e(s2) − c_e(s1))/(s2 − s1),   offset_e = c_e(s1) − lean_e·s1.
// The line is reported as ISO 230-1 location errors relative to the machine axes (the other rotary axis at 0):
// the position where it crosses the plane s = 0 (E_X0, E_Y0, E_Z0) and the right-hand rotation turning the
// nominal direction onto it (E_A0, E_B0, E_C0).
//
// How the paper's printed formulas read in this language. Our copy of the paper has lost its mathematical minus
// signs but keeps the explicit "+" of positive results; reading the printed numbers of Tables 3 and 4 through
// (1), (2), (4)–(7) that way, every angle of the paper is an ISO right-hand rotation relative to the machine axes
// (α = E_A0, β = E_B0, γ = E_C0) when the bar points towards −X in "C-X", +Y in "C-Y", +X in "B-X", +Z in "B-Z"
// and +Z (spindle ball above the table ball) in the XYC test [G: the bar directions are inferred from the signs,
// the paper's figures do not say]. Under that reading eq. (7) carries a minus sign (α = −(rz2 − rz1)/dy: Table 4
// gives rz2 − rz1 = −1.4 µm and (7) prints +1.4 µm/271 mm), and so do eq. (3)'s δy (δy = −ry1 + α·Z1) and eq. (5)
// (α = −Δy/R). The paper* functions below are those literal formulas; axisLineFromShifts is the general form for
// any bar direction and any axis, and agrees with them for the paper's setups.
#include <string>

#include <Eigen/Core>

#include "cnccomp/geometry.hpp"

namespace cnccomp::identification {

/// Centre shifts of an axis along one machine axis at two positions along the rotary axis.
struct Dbb5ShiftPair {
    std::string run1, run2;  ///< the runs at s1 and s2
    double s1 = 0, s2 = 0;   ///< ball positions along the rotary axis (bed frame), mm
    double c1 = 0, c2 = 0;   ///< centre shifts, mm
};

/// The average line of a rotary axis relative to the machine axes.
struct Dbb5AxisLine {
    std::string axis;            ///< rotary axis name (e.g. "C")
    int along = 2;               ///< machine axis (0 X, 1 Y, 2 Z) the rotary axis is nominally parallel to
    int first = 0, second = 1;   ///< the other two machine axes, (first, second, along) right-handed
    Dbb5ShiftPair shiftFirst, shiftSecond;  ///< the centre shifts along `first` and `second`
    Vec3 position = Vec3::Zero();  ///< where the line crosses the plane s = 0 (component `along` is 0), mm
    Vec3 rotation = Vec3::Zero();  ///< right-hand rotation vector from the nominal direction (component `along` 0), rad

    /// ISO 230-1 names of the position along machine axis k ("EX0C") and of the rotation about it ("EA0C").
    std::string positionName(int k) const;
    std::string rotationName(int k) const;
};

/// Centre shift along machine axis `e` (0..2) of a rotary run with bed-frame bar direction `u` (table ball →
/// spindle ball) and mean radial error r: c_e = −r/(u·e). Throws ModelError when u is (nearly) ⟂ e.
double dbb5CentreShift(double meanRadialError, const Vec3& u, int e);

/// The line through the centre shifts (general form of eq. (1)–(3) and (6)–(7)). Throws ModelError for
/// coincident positions or an axis index outside 0..2.
Dbb5AxisLine axisLineFromShifts(const std::string& axis, int along, const Dbb5ShiftPair& first,
                                const Dbb5ShiftPair& second);

/// The same description of an exact line (a point and a direction, bed frame); used to compare a model with the
/// formulas. Throws ModelError when the direction is far (> 60°) from machine axis `along`.
Dbb5AxisLine axisLineFromGeometry(const std::string& axis, int along, const Vec3& point, const Vec3& direction);

/// Eq. (1)–(3) as printed (C axis; mean radial errors of C-X and C-Y at heights Z1 < Z2, mm): β = (rx2 − rx1)/dz,
/// α = (ry2 − ry1)/dz, δx = rx1 − β·Z1, δy = −ry1 + α·Z1 (ISO EB0C, EA0C, EX0C, EY0C relative to the machine axes).
struct Dbb5PaperInnerAxis {
    double beta = 0, alpha = 0, dx = 0, dy = 0;
};
Dbb5PaperInnerAxis paperInnerAxis(double rx1, double ry1, double rx2, double ry2, double Z1, double Z2);

/// Eq. (6)–(7) as printed (B axis; mean radial errors of B-X and B-Z at positions y1 < y2, mm):
/// γ = (rx2 − rx1)/dy, α = −(rz2 − rz1)/dy (ISO EC0B, EA0B relative to the machine axes).
struct Dbb5PaperOuterAxis {
    double gamma = 0, alpha = 0;
};
Dbb5PaperOuterAxis paperOuterAxis(double rx1, double rz1, double rx2, double rz2, double y1, double y2);

/// Eq. (4)–(5): tilts of the C axis from the centre offset (Δx, Δy) of the XYC test profile, radius R:
/// β = Δx/R, α = −Δy/R (ISO EB0C, EA0C relative to the XY plane of motion).
struct Dbb5PaperTilt {
    double beta = 0, alpha = 0;
};
Dbb5PaperTilt paperXycTilt(double dx, double dy, double R);

}  // namespace cnccomp::identification
