#pragma once
// The ISO 230-2 positioning error of one linear axis (laser_positioning.hpp) as that axis' positioning component
// error in a deviation set (EXX for X, EYY for Y, EZZ for Z: ISO 230-1:2012 3.4.7 "positioning error motion",
// README "Deviation names and signs"), so that it joins the squareness and the rotary-axis deviations in one set and in
// the volumetric map (volumetric_map.hpp).
//
// What goes in: the mean bidirectional positional deviation x̄(P) = (x̄↑(P) + x̄↓(P)) / 2 (ISO 230-2 clause 2), as a
// function of position (linear between the targets, constant beyond them), and the axis' mean reversal value
// B̄ = mean of B_i = x̄_i↑ − x̄_i↓ (ISO 230-2 clause 2) as its reversal value (DeviationSet::reversal, row B<axis>), in
// the laser's frame (the reading below: no sign from the kinematics). The reversal depends on the approach direction:
// the kinematics and the volumetric map leave it out; the controllers take it as backlash. What one value cannot hold,
// B_i target by target (max |B_i − B̄|), stays in the laser route's two-column tables.
//
// Sign and scale come from the machine's own kinematics (as the circle route's squareness, linear_circle_identify):
// the laser reads the tool's displacement relative to the workpiece along the direction in which a positive command of
// the axis moves the tool relative to the workpiece (ISO 230-2 clause 2: actual − target along the axis); the
// component's effect on that reading per unit value, s (+1 for a slide on the tool side whose component is along its
// own direction, −1 for a table slide described by its motion in the bed frame), is computed from the exact model at
// the targets with the other axes at 0 (or mid-travel when 0 is outside it), and the component is set to x̄ / s.
// Bases: a table (the pitch-table form): each node gets x̄(node)/s; a polynomial (terms q¹..qⁿ, no constant): least
// squares over the targets, with the largest residual returned. Targets are the controller's machine coordinates (the
// laser's), converted to the description's commands with the axis' machine zero (MachineModel::fromController).
#include <string>
#include <vector>

#include "cnccomp/deviations.hpp"
#include "cnccomp/laser_positioning.hpp"

namespace cnccomp {

struct LaserComponentResult {
    std::string component;        ///< deviation name set, e.g. EXX
    double sensitivity = 0;       ///< s: laser reading per unit component value (±1 for the usual descriptions)
    double largestResidualUm = 0; ///< max |x̄_i − s·e(P_i)| over the targets, µm (0 for a table with nodes at the targets)
    double meanReversalUm = 0;    ///< B̄, µm (also the set's reversal value of the axis)
    double reversalUm = 0;        ///< B = max |B_i|, µm (not in the set)
    int nodesOutside = 0;         ///< table nodes outside the measured targets (given the end targets' value)
};

/// Which component of the machine holds the positioning error of `axis` (E<axis><axis>) and how a laser reads it: the
/// deviation's index and the sensitivity s (reading per unit value, from the exact model at `atCommand`, the other axes at
/// 0 or mid-travel). ModelError as setPositioningComponent.
struct PositioningComponent {
    int deviation = -1;
    double sensitivity = 0;
};
PositioningComponent positioningComponent(const MachineModel& m, const std::string& axis, double atCommand);

/// Sets the positioning component of the laser's axis (E<axis><axis>) and its reversal value (B̄) in `set` from the
/// laser result. Throws
/// ModelError when the machine has no such axis or component, the component is not of that axis' link or has a
/// Fourier basis, or does not move the tool along the axis (|s| < 0.5); InputError (file = the laser's source) when a
/// target is outside the axis' travel.
LaserComponentResult setPositioningComponent(DeviationSet& set, const LaserPositioningResult& laser,
                                             const std::string& laserSource = {});

/// `base` with every deviation present in `update` replaced by update's: location errors by their ISO value (the
/// others keep theirs), component errors coefficient by coefficient, reversal values axis by axis. Both sets must be of the same machine object.
DeviationSet mergeDeviations(const DeviationSet& base, const DeviationSet& update);

/// What mergeDeviations does with the reversal values (rows B<axis>), one line per axis that either set holds, for
/// the output of `--merge`: a value the update determined replaces the base's ("BX = -4.0000 um from <updateName>
/// (replaces the base's -3.0000 um)"), one it did not determine keeps the base's ("BZ = -3.0000 um kept from the base
/// (<updateName> did not determine it)"). Empty when neither set has a reversal value.
std::vector<std::string> reversalMergeLines(const DeviationSet& base, const DeviationSet& update, const std::string& updateName);

}  // namespace cnccomp
