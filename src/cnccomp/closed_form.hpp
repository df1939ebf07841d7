#pragma once
// Closed-form identification of seed 000, section 5: equations (17)–(28) give the 12 identifiable
// deviations of the w-C'bZYXB(C1)-t machine from the eccentricities of six ball-bar runs
// (B-X, B-Y, C-axial, C-radial at (ZC, RB), (ZC', RB), (ZC', RB'')). γXY is not identified.
#include <vector>

#include "cnccomp/deviations.hpp"
#include "cnccomp/eccentricity.hpp"

namespace cnccomp {

/// The runs the closed-form method needs, picked out of a table; the three C-radial rows are told apart by
/// their geometry. Throws ModelError naming what is missing or inconsistent.
struct ClosedFormInputs {
    EccentricityRow bx, by, ca, cr, crZ, crR;  ///< crZ: (ZC', RB); crR: (ZC', RB'')
};
ClosedFormInputs selectClosedFormInputs(const std::vector<EccentricityRow>& rows);

/// Equations (17)–(28). The machine must define the deviations by their seed-000 aliases
/// (dxBT dzBT aBT aXB bXB gXB aYZ bYZ dxCZ dyCZ aCZ bCZ); the result marks those 12 present.
DeviationSet identifyClosedForm(const MachineModel& machine, const std::vector<EccentricityRow>& rows);

}  // namespace cnccomp
