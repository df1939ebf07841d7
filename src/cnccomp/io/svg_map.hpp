#pragma once
// SVG picture of a volumetric map: colour map of |tip error| on one plane of the grid, with arrows showing the
// in-plane error components (clipped to the plot frame), axes labelled with what the coordinates are (machine axis
// commands, or tool-tip position in the workpiece frame) and their units, a colour bar in µm starting at 0 (its top
// can be shared between maps shown side by side) and a title. A plane without error says so.
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "cnccomp/volumetric_map.hpp"

namespace cnccomp::io {

/// "XY@Z=0" or "XZ@Y=100,B=30": two grid axes spanning the picture (horizontal, vertical) and the values at which
/// the other grid axes are cut (grid axes not named are cut at their value nearest 0).
struct MapPlane {
    std::string u, v;
    std::vector<std::pair<std::string, double>> at;  ///< name, value (mm or deg as in the grid)
};
MapPlane parseMapPlane(std::string_view text);

struct SvgInfo {
    std::string title;     ///< e.g. machine and deviation set
    /// Top of the colour scale in µm (the scale always starts at 0); 0 = the plane's own largest |e|. Give maps shown
    /// side by side (before / after compensation) the same value so that one colour is one error everywhere.
    double scaleMaxUm = 0;
    /// Prefix of the ids inside the picture (marker, gradient, clip path), so that several pictures can share one
    /// HTML page.
    std::string idPrefix = "map";
};

/// Largest |tip error| on the plane, mm (throws like renderMapSvg).
double planeMaxError(const VolumetricMap& map, const MapPlane& plane);

/// Renders the plane (throws InputError("--plane") when the plane axes are not varying grid axes or a cut value
/// is not on the grid).
std::string renderMapSvg(const VolumetricMap& map, const MachineModel& machine, const MapPlane& plane,
                         const SvgInfo& info);
/// Flat grid indices of the plane's points, u-major (throws like renderMapSvg; map.points is not read): what a
/// streamed map keeps for its picture.
std::vector<long> planePointIndices(const VolumetricMap& map, const MapPlane& plane);
/// The same picture from the plane's points alone (`planePoints[k]` is the point at planePointIndices(map, plane)[k];
/// map.points is not read): the picture of a streamed map.
std::string renderMapSvg(const VolumetricMap& map, const std::vector<MapPoint>& planePoints, const MachineModel& machine,
                         const MapPlane& plane, const SvgInfo& info);

}  // namespace cnccomp::io
