#pragma once
// Units at the edges. Inside the library: mm and radians.
#include <optional>
#include <string_view>

namespace cnccomp {

enum class Quantity { Length, Angle };

struct UnitInfo {
    Quantity quantity;
    double toInternal;  ///< multiply a value in this unit to get mm or rad
};

/// Recognised: um (µm), mm, arcsec, urad (µrad), um/m (µm/m, = µrad), rad, deg. Empty if unknown.
std::optional<UnitInfo> parseUnit(std::string_view unit);

}  // namespace cnccomp
