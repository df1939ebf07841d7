#pragma once
// SVG picture of a volumetric map: colour map of |tip error| on one plane of the grid, with arrows showing the
// in-plane error components, axes with ticks and units, a colour bar and a title.
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "cnccomp/volumetric_map.hpp"

namespace cnccomp {

/// "XY@Z=0" or "XZ@Y=100,B=30": two grid axes spanning the picture (horizontal, vertical) and the values at which
/// the other grid axes are cut (grid axes not named are cut at their value nearest 0).
struct MapPlane {
    std::string u, v;
    std::vector<std::pair<std::string, double>> at;  ///< name, value (mm or deg as in the grid)
};
MapPlane parseMapPlane(std::string_view text);

struct SvgInfo {
    std::string title;     ///< e.g. machine and deviation set
};

/// Renders the plane (throws InputError("--plane") when the plane axes are not varying grid axes or a cut value
/// is not on the grid).
std::string renderMapSvg(const VolumetricMap& map, const MachineModel& machine, const MapPlane& plane,
                         const SvgInfo& info);

}  // namespace cnccomp
