#pragma once
// The deviation set's reversal values (DeviationSet::reversal, ISO 230-2 mean reversal B̄, rows B<axis>) as the one
// backlash value per axis that Fanuc (1851), Sinumerik (MD32450), HEIDENHAIN (MP710 / MP_backLash) and ISG
// (P-AXIS-00103) hold, for `emit`, and how those controls apply it, for their apply models (`verify`).
//
// The value: β = −B̄ (laser_axis.hpp: the backlash is the extra travel the motor makes, in its direction of motion, when
// the axis moves against the reference approach; positive for the usual lost motion, the slide lagging its motor; the
// same for either reference direction). Positive for the usual case in every vendor's text: Fanuc B-64120EN p.116 (1851, "backlash compensating
// value"), SINUMERIK 808D Parameter Manual 08/2013 p.228 (MD32450 BACKLASH: "positive, if the encoder is leading the
// machine part (normal situation)"), HEIDENHAIN TNC 426/430 Technical Manual 6.4.1 (MP710: "Positive backlash: The
// rotary encoder reading is ahead of the table. The table traverse is too short"), Beckhoff TF5200 axis compensation
// P-AXIS-00103 ("0 < backlash: backlash between drive and slide").
// The action (apply models): after the reference approach in +, the control adds β in the direction of motion while
// the axis moves −, nothing while it moves + (Fanuc 1851: "When the machine moves in a direction opposite to the
// reference position return direction ..., the first backlash compensation is performed"; ISG P-AXIS-00021 = 1 "last
// axis motion occurred in pos. direction"; Sinumerik and HEIDENHAIN add it at every reversal [G: the side they start
// from]). A pose whose direction is not known (0) gets the mean, −β/2. The ramps some controls spread the step over
// (HEIDENHAIN MP752 / MP_filterTime, ISG P-AXIS-00243) are not modelled: the value after the ramp.
#include <string>
#include <vector>

#include "controllers/backend.hpp"

namespace cnccomp::controllers::common {

/// β (µm) from a mean reversal value B̄ (µm): −B̄, whichever the reference approach. Approach in +: moving − the slide
/// stays x̄↓ − x̄↑ = −B̄ above the target, so the motor goes −B̄ further in its direction of motion; approach in −: moving
/// + it stays x̄↑ − x̄↓ = B̄ below, so the motor goes −B̄ further in its direction of motion again (Fanuc 1851: "the
/// direction for compensating values is the direction of movement").
inline double backlashFromMeanReversalUm(double meanReversalUm) { return -meanReversalUm; }

struct AxisBacklash {
    int axis = -1;            ///< machine axis index
    std::string name;         ///< axis name (X, Y, Z)
    double reversalUm = 0;    ///< B̄, µm
    double backlashUm = 0;    ///< β, µm
};

/// The set's reversal values of the request's machine, as β (reference approach in + [G: the usual]), in axis order.
std::vector<AxisBacklash> backlashOfSet(const EmitRequest& request);

/// The drive offset (mm or the axis' unit) of a control holding backlash β that moves with `motion` (+1, −1, 0 = not
/// known: the mean), reference approach in +: −β while moving −, 0 while moving +, −β/2 unknown.
inline double backlashDriveOffset(double beta, double motion) { return motion < 0 ? -beta : motion > 0 ? 0.0 : -0.5 * beta; }

/// `drive` with each axis' backlash offset (betaPerAxis in the description's units, one per axis or empty).
AxisVector withBacklashOffsets(const AxisVector& drive, const std::vector<double>& betaPerAxis, const AxisVector& motion);

}  // namespace cnccomp::controllers::common
