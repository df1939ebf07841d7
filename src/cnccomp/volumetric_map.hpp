#pragma once
// Volumetric error map: over a grid of axis commands (or of tool-tip positions at a fixed tool orientation),
// the tool-tip position error (dx, dy, dz) and the tool-orientation error between tool and workpiece of the
// erroneous machine against the nominal one, both with the exact model (Kinematics, toolPose) — the volumetric
// counterpart of the papers' single-point error models ([MultiTasking] eq. (7), (10), (15); [RotaryTableModel] eq. for the tool
// pose in the table frame). Computed in parallel (std::thread), no allocation per point, block by block: a map
// can be streamed to a file without ever being held whole.
#include <array>
#include <optional>
#include <span>
#include <vector>

#include "cnccomp/deviations.hpp"
#include "cnccomp/map_grid.hpp"

namespace cnccomp {

struct MapRequest {
    const MachineModel& machine;
    const DeviationSet& deviations;
    MapGrid grid;
    double toolLength = 0.0;  ///< mm, along the machine's tool direction from the last tool-chain frame
    /// Empty: the grid names machine axes (linear mm, rotary deg); axes not named are held at 0.
    /// Set: unit tool axis (spindle → tip) in the workpiece frame; the grid names X, Y, Z = tool-tip position in
    /// the workpiece frame (mm), and every point's commands solve the nominal inverse kinematics.
    std::optional<Vec3> toolOrientation;
    int threads = 0;  ///< 0 = all cores
};

/// One grid point. Errors are actual − nominal, in the workpiece frame.
struct MapPoint {
    std::array<double, kMaxAxes> q{};  ///< axis commands (mm, rad), machine axis order
    Vec3 tip = Vec3::Zero();            ///< nominal tool tip in the workpiece frame, mm
    Vec3 error = Vec3::Zero();          ///< tip position error, mm
    Vec3 rotation = Vec3::Zero();       ///< rotation vector taking the nominal tool axis to the actual one, rad
    double tilt = 0.0;                  ///< angle between nominal and actual tool axis, rad
    bool ok = true;                     ///< false when the inverse kinematics failed (orientation mode)
};

struct ComponentStats {
    double maxAbs = 0.0;  ///< largest |value|
    double rms = 0.0;
};

struct MapStatistics {
    long points = 0;   ///< evaluated points (ok)
    long failed = 0;   ///< points where the nominal inverse kinematics did not converge or left the travel
    ComponentStats dx, dy, dz, norm, tilt;  ///< mm, mm, mm, mm, rad
    long worstIndex = -1;      ///< flat grid index of the largest |tip error|
    long worstTiltIndex = -1;  ///< flat grid index of the largest tilt
    MapPoint worst, worstTilt;
};

struct VolumetricMap {
    MapGrid grid;
    std::vector<std::string> axisNames;
    double toolLength = 0.0;
    std::optional<Vec3> toolOrientation;
    std::vector<MapPoint> points;  ///< grid.size() points, flat index order (last grid axis fastest)
    MapStatistics stats;
};

/// Receiver of a streamed map (streamMap): the grid's points in blocks of consecutive flat indices, every block once.
/// The default members do nothing.
class MapSink {
public:
    virtual ~MapSink() = default;
    /// Called once before any block: `slots` block buffers are in use at once (slot numbers 0 … slots − 1), each of
    /// at most `blockPoints` points.
    virtual void begin(int slots, long blockPoints) { (void)slots, (void)blockPoints; }
    /// Where to evaluate the block [first, first + count) (on a worker thread); nullptr: in the engine's own buffer.
    virtual MapPoint* storage(long first, long count) { return (void)first, (void)count, nullptr; }
    /// On a worker thread, as soon as a block is evaluated (blocks of other slots are evaluated at the same time):
    /// e.g. format it into the slot's own buffer.
    virtual void evaluated(int slot, long first, std::span<const MapPoint> points) { (void)slot, (void)first, (void)points; }
    /// On the calling thread, once per block in flat-index order, after that block's `evaluated` (while later blocks
    /// are evaluated): e.g. write it. The slot is not reused before this returns.
    virtual void inOrder(int slot, long first, std::span<const MapPoint> points) { (void)slot, (void)first, (void)points; }
};

/// The map of `request` without its points or statistics (grid, axis names, tool; the orientation normalised): what
/// a streamed map's file header and picture show.
VolumetricMap describeMap(const MapRequest& request);
/// Evaluates every grid point and keeps them. Throws ModelError/InputError on grid names the machine does not
/// have, or ranges outside the travel.
VolumetricMap computeMap(const MapRequest& request);
/// Statistics only (no storage proportional to the grid): the fast path for very large grids.
MapStatistics mapStatistics(const MapRequest& request);
/// Evaluates the grid block by block (all threads of the request) and hands every block to `sink`: memory does not
/// grow with the grid. Returns the statistics (the same as mapStatistics'; they are summed block by block and do not
/// depend on the thread count). Throws as computeMap, or what the sink throws (the workers are stopped first).
MapStatistics streamMap(const MapRequest& request, MapSink& sink);

}  // namespace cnccomp
