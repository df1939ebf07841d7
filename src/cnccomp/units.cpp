#include "cnccomp/units.hpp"

#include "cnccomp/geometry.hpp"

namespace cnccomp {

std::optional<UnitInfo> parseUnit(std::string_view u) {
    if (u == "um" || u == "µm" || u == "micron") return UnitInfo{Quantity::Length, 1e-3};
    if (u == "mm") return UnitInfo{Quantity::Length, 1.0};
    if (u == "arcsec") return UnitInfo{Quantity::Angle, kArcsec};
    if (u == "urad" || u == "µrad" || u == "um/m" || u == "µm/m") return UnitInfo{Quantity::Angle, 1e-6};
    if (u == "rad") return UnitInfo{Quantity::Angle, 1.0};
    if (u == "deg") return UnitInfo{Quantity::Angle, kDeg};
    return std::nullopt;
}

}  // namespace cnccomp
