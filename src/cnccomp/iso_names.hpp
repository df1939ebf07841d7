#pragma once
// What the ISO 230-1 / ISO 230-7 names of a machine's deviations mean, as linear combinations of the link values
// (the error components of the kinematic chains that the flat deviation vector holds and the kinematics use).
//
// A deviation named E<e>0<T> (e in X Y Z A B C, T a link of the machine) is read as ISO 230-1:2012 defines it
// (section 3.4 notation, 3.6.7 squareness; ISO 230-7:2015 for the axes of rotation), to first order:
//  - the error is that of the target T's line and frame: X Y Z = position (a translation along +X +Y +Z),
//    A B C = orientation, a right-hand rotation about +X +Y +Z (about the axis itself: its zero position);
//  - reference coordinate system of the linear axes (squareness and the location of axes carried by the bed or the
//    slides): x along the X motion, y in the plane of the X and Y motions, z = x × y, i.e. X primary and Y
//    secondary, so EC0Y is Y turned about +Z relative to X (angle X∠Y = 90° + EC0Y), EB0Z is Z turned about +Y
//    relative to X (Z∠X = 90° − EB0Z), EA0Z is Z turned about +X relative to Y (Y∠Z = 90° + EA0Z). A machine that
//    declares another squareness of a pair (EC0X: X turned relative to Y) takes the other axis of that pair as the
//    reference for that rotation;
//  - an axis carried by an axis of rotation (C on an A cradle, a spindle on a swivel head) is located relative to
//    the carrier's frame at its zero position (ISO's EX(0A)C notation); a fixed link (spindle, table) relative to
//    the link it sits on. Then the name's value is the link's own error component.
// Names that do not follow the pattern, or whose target is not a link, mean the link's own error component.
// Sources: ISO 230-1:2012 section 3.6.7 (squareness: the difference between the inclinations of the reference straight
// lines of two axes), as quoted in M.A.V. Chapman, "Calibration of machine squareness", Renishaw white paper TE328;
// the E<e>0<axis> notation of the location errors as listed in Beckhoff TF5280 "List of parameters supported (DIN ISO
// 230)" (infosys.beckhoff.com); the rotation sign (right-hand rule) and the X-primary/Y-secondary reference are the
// usual reading of the standard, not quoted from it [G].
// The paper aliases are aliasSign × link value (DeviationDef::aliasSign, machine XML `alias-sign`).
// Component errors (EXX …) are the link's own error functions under either name.
#include <string>

#include "cnccomp/machine.hpp"

namespace cnccomp {

/// Fills DeviationDef::isoTerms and ::linkTerms of every deviation (called by MachineModel::finalize). Throws
/// ModelError when a name's quantity does not depend on its own link (e.g. 'EC0Y' declared on a link whose error
/// cannot turn Y relative to X), when two names describe the same quantity, or when a machine declares both
/// squareness errors of one pair about the same axis (EC0X and EC0Y).
void deriveIsoMeaning(MachineModel& machine);

/// True when deviation `index` has an alias that gives a different number than its ISO name for the same geometry
/// (another sign, or an ISO value that involves other link values).
bool aliasDiffersFromName(const MachineModel& machine, int index);

/// "EA0C = aCZ - aYZ": the ISO value of a location deviation in terms of the link values, each link value spelled
/// by its alias when the alias carries the link's sign, else as [link.component].
std::string isoMeaningText(const MachineModel& machine, int deviation);

}  // namespace cnccomp
