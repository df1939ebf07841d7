#pragma once
// The generic backend's grid map: over a tensor grid of axis commands, the tool-tip position error at tool length 0
// and the error of the unit tool-axis vector, so that the error at any tool length L is e0 + L·dk. Errors of the tool
// relative to the workpiece, expressed along the machine's X Y Z (the bed frame: the workpiece-frame error turned by
// the nominal workpiece orientation), which is where a controller adds a volumetric correction. In that frame a
// table-side rotary axis' location errors do not turn with the axis, so the map needs nodes only where the error
// really changes. Exact model (Kinematics); the reader interpolates multilinearly (a modulo axis spanning one turn
// wraps), as a controller with an N-dimensional lookup table would. The files give the axis positions in the
// controller's machine coordinates (command − Link::machineZero); GridMap holds the description's commands.
#include <string>
#include <vector>

#include "cnccomp/kinematics.hpp"

namespace cnccomp::controllers::generic {

struct GridMapAxis {
    int axis = -1;            ///< machine axis index
    bool rotary = false;
    bool wraps = false;       ///< modulo axis whose nodes span exactly one turn
    std::vector<double> nodes;  ///< internal units, strictly increasing
};

struct GridMap {
    std::vector<GridMapAxis> axes;  ///< all machine axes, in machine order; the last varies fastest
    std::vector<Vec3> tip;          ///< mm, per node (flat, row-major), machine frame
    std::vector<Vec3> toolAxis;     ///< unit-vector error (dimensionless = rad for small tilts), machine frame
    double tolerance = 0;           ///< buildGridMap: the interpolation tolerance the nodes were chosen for, mm
    /// Interpolated errors at commands q (no allocation).
    void at(const AxisVector& q, Vec3& tipError, Vec3& axisError) const;
};

/// The map's values at commands q: tip error at tool length 0 and tool-axis error, machine (bed) frame.
void machineFrameError(const Kinematics& nominal, const Kinematics& actual, const AxisVector& q, Vec3& tipError,
                       Vec3& axisError);

struct GridMapOptions {
    /// Largest deviation of the multilinear interpolation from the exact tip error (midway between nodes), mm.
    double tolerance = 0.05 * kUm;
    /// The tolerance holds for tool lengths 0 .. this (mm): the tool-axis error counts with this lever.
    double toolLength = 500.0;
    /// Node budget (about 130 bytes of map.csv each): when the tolerance needs more nodes, it is doubled until the
    /// grid fits (GridMap::tolerance says which it was).
    long maxNodes = 50'000;
};

/// Nodes per axis over its travel (rotary axes clamped to ±180°): the ends, the nodes of the axis' table-type component
/// errors, and between them as many evenly spaced nodes as keep the interpolation within `tolerance` (checked midway
/// between nodes with the other axes at their ends, middles and every 30°). Location errors alone leave the tip error
/// affine in each linear axis: two nodes; in the machine frame a table-side rotary axis' own location errors do not
/// need nodes on that axis either. When the grid would exceed maxNodes the tolerance is doubled until it fits; throws
/// ModelError when even the ends and table nodes exceed it.
GridMap buildGridMap(const MachineModel& m, const DeviationSet& d, const GridMapOptions& options = {});

std::string formatGridMapCsv(const GridMap& g, const MachineModel& m, const std::string& header);
std::string formatGridMapJson(const GridMap& g, const MachineModel& m, const std::vector<std::string>& header);
/// Reads map.csv for a machine; InputError(file:line) on missing axis columns, a grid that is not a full tensor
/// grid in row-major order, non-numbers.
GridMap parseGridMapCsv(const std::string& text, const std::string& file, const MachineModel& m);

}  // namespace cnccomp::controllers::generic
