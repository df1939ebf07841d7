#pragma once
// Volumetric map CSV: '#' header lines (machine, deviation set, grid, tool, statistics), then one row per grid
// point: every machine axis command (mm / deg), the nominal tip in the workpiece frame (mm), the tip error
// (um), the tool-orientation error as a rotation vector and tilt angle (arcsec), and ok (1/0).
#include <span>
#include <string>
#include <vector>

#include "cnccomp/volumetric_map.hpp"

namespace cnccomp::io {

struct MapCsvInfo {
    std::string machine;         ///< machine name
    std::string deviationSource; ///< deviation file
    /// Non-empty when the set has reversal values: the line saying the map leaves them out (it is direction-free).
    std::string reversalNote{};
};

/// Text of the map file.
std::string formatMapCsv(const VolumetricMap& map, const MachineModel& machine, const MapCsvInfo& info);
/// Appends the rows of `points` to `out`: the text writeMapCsv writes after the header.
void appendMapRows(std::span<const MapPoint> points, const MachineModel& machine, std::string& out);
/// Writes the map atomically.
void writeMapCsv(const std::string& path, const VolumetricMap& map, const MachineModel& machine, const MapCsvInfo& info);
/// The map of `request` written to `path` as writeMapCsv would write computeMap's map, byte for byte, without holding
/// it: the rows are formatted on the worker threads block by block (streamMap) and written in order (atomically). The
/// header's statistics come first: with machine axes a statistics pass precedes the one that writes; with a fixed
/// orientation (an inverse kinematics per point) the grid is evaluated once and its rows go through an anonymous
/// temporary file. Memory does not grow with the grid. `keep` (flat grid
/// indices, increasing) names points to copy into `kept` in that order (e.g. the plane of a picture). Returns the
/// statistics.
MapStatistics streamMapCsv(const std::string& path, const MapRequest& request, const MapCsvInfo& info,
                           std::span<const long> keep = {}, std::vector<MapPoint>* kept = nullptr);

/// A map file read back: the axis names of its columns and its points (internal units: mm, rad).
struct MapCsvTable {
    std::vector<std::string> axisNames;
    std::vector<MapPoint> points;
};
/// Reads a map CSV; throws InputError with file:line on missing columns or bad numbers.
MapCsvTable readMapCsv(const std::string& path);

/// Statistics lines shared by the CSV header and the `cnccomp map` output (no comment prefix).
std::vector<std::string> formatMapStatistics(const VolumetricMap& map, const MachineModel& machine);

}  // namespace cnccomp::io
