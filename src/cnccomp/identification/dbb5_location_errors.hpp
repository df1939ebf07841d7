#pragma once
// Location errors of the two rotary axes of a tilting rotary table (B/C as in the paper, or A/C) and squareness of
// the linear axes from DBB5 runs, with the ISO 230-4 figures of every run — S. Ibaraki, Y. Kakino, T. Akai,
// N. Takayama, I. Yamaji, K. Ogawa, "Identification of motion error sources on five-axis machine tools by ball-bar
// measurements (1st report)", sections 4.1–4.3, Tables 3 and 4.
//  - Linear circles XY, YZ, ZX (rotary axes still): out-of-squareness 90° − ∠(+P, +Q) = 2·b2/LB of the circle in
//    plane PQ, b2 the sin 2θ term of ΔL (ISO 230-4).
//  - Inner axis (C) turning, outer at 0, bar along the two machine axes ⟂ C, table ball at two positions along C:
//    the C line relative to the machine axes (eq. (1)–(3), dbb5_axis_line.hpp).
//  - Outer axis (B) turning (arcs), inner at 0, bar along the two machine axes ⟂ B, ball at two positions along B:
//    the B line (eq. (6)–(7)).
// Output, three ways, never a value under another definition's name:
//  - `formulas`: the plain formula values with the paper's definitions (relative to the machine axes; ISO 230-1
//    right-hand rotations; the inner axis with the outer at 0) — labelled, not a deviation set;
//  - `plain`: the same geometry converted to this machine model's deviations (the inner axis' location is stored
//    relative to the outer axis' frame, so e.g. the model's EY0C is the C line's Y position minus what B's location
//    contributes; squareness with the model's sign) — a change of definitions only, the formulas' first-order mixing
//    (e.g. squareness of the linear axes moving the rotary runs' readings) is kept;
//  - `deviations`: Gauss–Newton refinement on the exact model (reading_refinement.hpp) — the errors whose simulated runs
//    give the measured readings; refine = 0 returns `plain`.
#include <string>
#include <vector>

#include "cnccomp/deviations.hpp"
#include "cnccomp/identification/dbb5_axis_line.hpp"
#include "cnccomp/identification/dbb5_circular.hpp"
#include "cnccomp/identification/dbb5_run.hpp"

namespace cnccomp::identification {

struct Dbb5LocationOptions {
    /// Tilting (outer) and rotary table (inner) axes; empty = the two rotary axes of the workpiece chain, the one
    /// nearer the bed outer.
    std::string outerAxis, innerAxis;
    int refine = 4;  ///< Gauss–Newton steps on the formula readings (0 = the plain formulas, converted)
};

struct Dbb5RunReport {
    std::string run;
    CircularTestResult iso;  ///< ISO 230-4 on the measured (raw) trace
};

/// Out-of-squareness of the three planes, 90° − ∠(+P, +Q), rad, from the elliptic terms b2 (mm) of the circles.
struct Dbb5Squareness {
    double xy = 0, yz = 0, zx = 0;
    double b2XY = 0, b2YZ = 0, b2ZX = 0;
};

/// One plain-formula value with its definition.
struct Dbb5FormulaValue {
    std::string name;        ///< ISO name or the quantity ("EX0C", "90deg - angle(X,Y)")
    std::string definition;  ///< what it is relative to, its sign, the equation
    double value = 0;        ///< mm or rad
    bool angle = false;
};

struct Dbb5LocationResult {
    DeviationSet deviations;  ///< refined (model definitions); the identified ones are present
    DeviationSet plain;       ///< the plain formulas converted to the model's definitions
    std::vector<Dbb5FormulaValue> formulas;  ///< the plain formulas with the paper's definitions
    std::vector<std::string> identified;     ///< model deviation names, in the order of `formulas`
    std::string outerAxis, innerAxis;
    Dbb5AxisLine outer, inner;               ///< the formulas' lines (outer: inner at 0; inner: outer at 0)
    Dbb5Squareness squareness;
    std::vector<Dbb5RunReport> runs;         ///< every run of the plan, in order
    int refine = 0;
};

/// Throws ModelError naming the missing runs (a linear circle per plane; per rotary axis two runs with the bar along
/// each machine axis ⟂ it at two positions, the other rotary axis at 0) or deviations the machine lacks.
Dbb5LocationResult dbb5LocationErrors(const MachineModel& m, const std::vector<measurement::Dbb5Run>& runs,
                                      const std::vector<BallbarTrace>& traces, const Dbb5LocationOptions& options = {});

/// The outer and inner rotary axes (names) of a tilting rotary table: `options` if given, else the two rotary axes of
/// the workpiece chain in chain order. Throws ModelError when there are not exactly two.
std::pair<std::string, std::string> dbb5TableAxes(const MachineModel& m, const Dbb5LocationOptions& options = {});

/// The model deviations the formulas identify, in the order of `formulas`: EC0Y, EA0Z, EB0Z, then per axis (outer,
/// inner) its location deviations along and about the two machine axes ⟂ it (found by link and component).
std::vector<int> dbb5LocationDeviations(const MachineModel& m, const Dbb5LocationOptions& options = {});

/// The same quantities as `formulas` for a deviation set, from the model's geometry: the axis lines (joint frames at
/// all rotary axes 0, bed frame) and the angles between the relative X, Y, Z motions. Order as `formulas`.
Eigen::VectorXd dbb5GeometricReadings(const Kinematics& k, const std::string& outerAxis, const std::string& innerAxis);

}  // namespace cnccomp::identification
