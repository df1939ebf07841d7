#pragma once
// The generic backend's grid map: over a tensor grid of axis commands, the tool-tip position error at tool length 0
// (workpiece frame) and the error of the unit tool-axis vector, so that the error at any tool length L is
// e0 + L·dk. Exact model (Kinematics); the reader interpolates multilinearly (a modulo axis spanning one turn
// wraps), as a controller with an N-dimensional lookup table would. The files give the axis positions in the
// controller's machine coordinates (command − Link::machineZero); GridMap holds the description's commands.
#include <string>
#include <vector>

#include "cnccomp/deviations.hpp"

namespace cnccomp::controllers::generic {

struct GridMapAxis {
    int axis = -1;            ///< machine axis index
    bool rotary = false;
    bool wraps = false;       ///< modulo axis whose nodes span exactly one turn
    std::vector<double> nodes;  ///< internal units, strictly increasing
};

struct GridMap {
    std::vector<GridMapAxis> axes;  ///< all machine axes, in machine order; the last varies fastest
    std::vector<Vec3> tip;          ///< mm, per node (flat, row-major)
    std::vector<Vec3> toolAxis;     ///< unit-vector error (dimensionless = rad for small tilts)
    /// Interpolated errors at commands q (no allocation).
    void at(const AxisVector& q, Vec3& tipError, Vec3& axisError) const;
};

/// Nodes per axis: linear axes 2 (ends of travel: the tip error of location errors is affine in a linear axis) or
/// 5 when the axis carries component errors; rotary axes every 30° over the travel clamped to ±180°.
GridMap buildGridMap(const MachineModel& m, const DeviationSet& d);

std::string formatGridMapCsv(const GridMap& g, const MachineModel& m, const std::string& header);
std::string formatGridMapJson(const GridMap& g, const MachineModel& m, const std::vector<std::string>& header);
/// Reads map.csv for a machine; InputError(file:line) on missing axis columns, a grid that is not a full tensor
/// grid in row-major order, non-numbers.
GridMap parseGridMapCsv(const std::string& text, const std::string& file, const MachineModel& m);

}  // namespace cnccomp::controllers::generic
