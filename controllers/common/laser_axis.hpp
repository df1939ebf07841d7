#pragma once
// What the controllers' axis compensations take from the ISO 230-2 laser runs of one linear axis
// (cnccomp/laser_positioning.hpp): a pitch-error table and a backlash value, or two tables (one per direction).
//
// One table + one backlash value (Fanuc 1851, Sinumerik MD32450, HEIDENHAIN, and ISG unilateral): the controls add the
// backlash on a reversal against the direction of the reference-point approach (Fanuc B-64120EN p.116, 1851: "When the
// machine moves in a direction opposite to the reference position return direction after the power is turned on, the
// first backlash compensation is performed"; "The positive or negative direction for compensating values is the
// direction of movement"; the others [G]). So the table is the error of the reference-approach direction (x̄↑ for an
// approach in +, the usual) and the backlash β (µm) the extra travel the motor makes in the other direction: moving −
// after a + approach the slide lags by x̄↓ − x̄↑ = −B_i, so β = −B̄; after a − approach, moving + it lags by x̄↑ − x̄↓ =
// B_i below, the motor again goes −B̄ further in its direction of motion: β = −B̄ for either reference direction
// (set_backlash.hpp; an earlier round wrote +B̄ for an approach in −, the sign of the lag rather than of the
// correction); positive for the usual lost motion. One value cannot follow B_i target by target: max |B_i − B̄| is left (reported).
// Servo mismatch (the ball-bar circle's "v lagging u", linear_circle_model.hpp) is not a table: it is the difference
// of the interpolating axes' position-loop gains (lag Δt = 1/kv_v − 1/kv_u); each backend names its gain parameter.
#include <string>
#include <vector>

#include "cnccomp/laser_positioning.hpp"

namespace cnccomp::controllers::common {

struct LaserAxisCompensation {
    bool referenceForward = true;           ///< the reference point is approached in + (the table is x̄↑)
    std::vector<double> positions;          ///< the laser's targets, mm (machine coordinates)
    std::vector<double> forwardUm, reverseUm;  ///< x̄_i↑, x̄_i↓, µm
    std::vector<double> referenceUm;        ///< x̄_i of the reference direction, µm
    double backlashUm = 0;                  ///< β = −B̄, µm, added in the direction of motion against the reference approach
    double backlashLeftUm = 0;              ///< max |B_i − B̄|, µm: what one backlash value leaves
};

LaserAxisCompensation laserAxisCompensation(const LaserPositioningResult& r, bool referenceForward = true);

/// The note on what no table holds, with the adjustment the engineer makes: servo mismatch → match the position-loop
/// gains of the interpolating axes (`gainParameter` names the control's parameter).
std::string servoMismatchNote(const std::string& gainParameter);

}  // namespace cnccomp::controllers::common
