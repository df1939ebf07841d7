#pragma once
// Seed 003 (Ibaraki et al., DBB5): location errors of the rotary axes and squareness of the linear axes of a
// table-table machine from DBB5 runs, with the ISO 230-4 circularity and mean radial error of every run
// (Tables 3 and 4).
//  - Linear circles XY, YZ, ZX (rotary axes still): out-of-squareness from the elliptic (sin 2θ) term b2 of ΔL:
//    EC0Y = 2·b2(XY)/LB, EA0Z = −2·b2(YZ)/LB, EB0Z = 2·b2(ZX)/LB (signs of this library's model, see seed001_rtest.hpp).
//  - Inner axis (C) turning, outer (A) at 0, bar along X ("C-X") and along Y ("C-Y"), the table ball at two heights
//    Z1 < Z2 (dz = Z2 − Z1). With r the mean radial error and c = −r/(u·e) the centre shift along the bar axis e:
//      βZ = (c_x2 − c_x1)/dz (1),  αZ = −(c_y2 − c_y1)/dz (2),  δx = c_x1 − βZ·Z1,  δy = c_y1 + αZ·Z1 (3).
//    With the bar towards −X / −Y, c = r and (1), (3) read as printed; (2) as printed has the opposite sign to (3)
//    under one convention — this library keeps (3) and the model's sign (EA0C turns C about +X).
//  - Outer axis (A) turning (an arc: its travel is less than a turn), inner at 0, bar along Y and along Z, the ball
//    at two positions x1 < x2 along A (eq. (6), (7) of the paper for its B axis, here for A about X):
//      EC0A = (c_y2 − c_y1)/dx,  EB0A = −(c_z2 − c_z1)/dx,  EY0A = c_y1 − EC0A·x1,  EZ0A = c_z1 + EB0A·x1.
// The mean radial error is the radius of the least-squares circle of the polar plot minus LB, i.e. the constant
// term of the full circle an arc belongs to (for a full turn, the mean of ΔL), so arcs are handled the same way.
// As in seed 001, the formula readings mix the errors to first order (e.g. the squareness of the linear axes shifts the
// spindle-ball circles of the rotary runs); `refine` Gauss–Newton steps on the exact model (seed001_refine.hpp) find
// the errors whose simulated runs give the measured readings; refine = 0 gives the plain formulas.
#include <string>
#include <vector>

#include "cnccomp/deviations.hpp"
#include "cnccomp/identification/dbb5_circular.hpp"
#include "cnccomp/identification/dbb5_run.hpp"

namespace cnccomp {

struct Dbb5LocationOptions {
    std::string outerAxis = "A", innerAxis = "C";
    int refine = 4;  ///< Gauss–Newton steps on the formula readings (0 = the plain formulas)
};

struct Dbb5RunReport {
    std::string run;
    CircularTestResult iso;  ///< ISO 230-4 on the measured (raw) trace
};

/// The paper's intermediate numbers for the measured data, mm and rad.
struct Dbb5LocationNumbers {
    double Z1 = 0, Z2 = 0, cx1 = 0, cx2 = 0, cy1 = 0, cy2 = 0;   ///< inner-axis runs
    double betaZ = 0, alphaZ = 0, dx = 0, dy = 0;                ///< eq. (1)–(3)
    double x1 = 0, x2 = 0, cyA1 = 0, cyA2 = 0, czA1 = 0, czA2 = 0;  ///< outer-axis runs
    double b2XY = 0, b2YZ = 0, b2ZX = 0;                         ///< elliptic terms of the linear circles
};

struct Dbb5LocationResult {
    DeviationSet deviations;          ///< the 11 errors, present (after refinement)
    DeviationSet plain;               ///< the plain formulas
    std::vector<Dbb5RunReport> runs;  ///< every run of the plan, in order
    Dbb5LocationNumbers numbers;
    int refine = 0;
};

/// Throws ModelError naming the missing runs (a linear circle per plane, two heights per bar direction …) or
/// deviations the machine lacks.
Dbb5LocationResult dbb5LocationErrors(const MachineModel& m, const std::vector<Dbb5Run>& runs,
                              const std::vector<BallbarTrace>& traces, const Dbb5LocationOptions& options = {});

}  // namespace cnccomp
