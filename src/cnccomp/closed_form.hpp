#pragma once
// Ball-bar eccentricity formulas (the paper-literal method of `identify --method formulas` on ball-bar plans): the
// identification of geometric deviations of multi-tasking machine tools with a swivel tool spindle head in a horizontal
// position by ball-bar measurements ([MultiTasking], section 5): equations (17)–(28) give the 12 identifiable
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

struct ClosedFormOptions {
    /// Defect-correction passes on the exact model. The formulas are first order; the exact ball-bar length adds
    /// second-order terms (e.g. |δ0|²/LB in the C-axial ex, δ0 = setup offset of the W-side ball ≈ 0.1 µm, i.e.
    /// 0.5 arcsec in βXB, βYZ after division by RC). Each pass simulates the rows' runs on the identified set,
    /// and feeds the eccentricity defect (measured − simulated) back through the same formulas. 0 = formulas only.
    int refinements = 3;
    double stepDeg = 1.0;  ///< sweep step of the simulated runs in the refinement
};

/// Equations (17)–(28). The machine must define the deviations by the paper's aliases
/// (dxBT dzBT aBT aXB bXB gXB aYZ bYZ dxCZ dyCZ aCZ bCZ, set as the paper's values: alias sign × link value); the
/// result marks those 12 present.
DeviationSet identifyClosedForm(const MachineModel& machine, const std::vector<EccentricityRow>& rows,
                                const ClosedFormOptions& options = {});

}  // namespace cnccomp
