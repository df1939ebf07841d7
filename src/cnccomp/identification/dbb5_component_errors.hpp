#pragma once
// Component errors of a rotary axis (ISO 230-7 error motions) from DBB5 profiles — the "component" half of Ibaraki,
// Kakino, Akai, Takayama, Yamaji, Ogawa, "Identification of motion error sources on five-axis machine tools by
// ball-bar measurements (1st report): classification of motion error components and ...", section 4.2.2 and Table 2.
//
// With the table ball on the turning axis and the bar along a machine axis e (fixed in the bed), the run's ΔL(θ)
// follows the ball's displacement along e as the axis turns: D_e(θ) = −ΔL(θ)/(u·e). Less what the axis' location
// errors make of it (simulated on the exact model with the identified location errors), it is the error motion of
// the axis at the ball: the paper's δx(C), δy(C) from C-X and C-Y, δz(C) from C-Z (bar along the axis). Balls at two
// positions s1 < s2 along the axis give the tilt error motions: along e_first, D(s) = δ + (s − s0)·ε_second, along
// e_second, D(s) = δ − (s − s0)·ε_first.
//
// Definitions (the paper's, Table 2: relative to the machine axes): δ(θ) and ε(θ) in the bed frame, relative to
// the axis average line (the location errors carry the average: ISO 230-7) and zero at the setup angle (θ = 0),
// where the table ball is set on the spindle ball. The angular positioning error (ECC) and a run-out that turns
// with the table (paper Fig. 2(b), constant in the table frame) do not move a ball on the axis and are not seen.
//
// This library's component tables (EXC … EBC, machine XML) are errors placed after the axis' rotation, in the
// turning frame; dbb5ComponentTables converts: t(θ) = R(θ)ᵀ·δ(θ), ω(θ) = R(θ)ᵀ·ε(θ), R(θ) the axis' nominal
// rotation, at the tables' nodes.
#include <string>
#include <vector>

#include "cnccomp/deviations.hpp"
#include "cnccomp/identification/dbb5_run.hpp"

namespace cnccomp::identification {

struct Dbb5ComponentProfile {
    std::string axis;
    int along = 2, first = 0, second = 1;  ///< machine axes as in Dbb5AxisLine
    /// Position along the axis (bed frame) the translations refer to: the axis frame's origin when runs at two
    /// positions give the tilts, else the position of the balls, mm.
    double reference = 0;
    bool axial = false;  ///< δ_along measured (a run with the bar along the axis)
    bool tilts = false;  ///< ε_first, ε_second measured (runs at two positions)
    std::vector<double> angleDeg;   ///< sweep angles, deg
    std::vector<Vec3> translation;  ///< δ(θ), bed frame, mm (unmeasured components 0)
    std::vector<Vec3> tilt;         ///< ε(θ), bed frame, rad (component `along` is never measured: 0)
    std::vector<std::string> runs;  ///< the runs used
};

/// Profiles of rotary axis `axis` from the plan's runs that turn it with the other rotary axes at 0, the ball on the
/// axis (within 0.01 mm) and the bar along a machine axis; `location` is the identified location set (its simulated
/// runs are subtracted). Throws ModelError naming what is missing (a run with the bar along each machine axis ⟂ the
/// axis) or runs whose sample angles differ.
Dbb5ComponentProfile dbb5ComponentProfile(const MachineModel& m, const std::vector<measurement::Dbb5Run>& runs,
                                          const std::vector<BallbarTrace>& traces, const DeviationSet& location,
                                          const std::string& axis);

/// `base` with the axis' component tables (basis "table") set from the profile at their nodes (linear interpolation
/// between the profile's angles, wrapping for a full turn), the filled ones marked present. Tables the profile does
/// not measure (rotation about the axis, axial without an axial run, tilts from one position) keep their values.
/// Throws ModelError for a component error of the axis that is not a table, or a node outside the measured angles.
DeviationSet dbb5ComponentTables(const MachineModel& m, const Dbb5ComponentProfile& profile, const DeviationSet& base);

}  // namespace cnccomp::identification
