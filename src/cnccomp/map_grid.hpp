#pragma once
// The grid of a volumetric error map: named axes with from:to:step ranges, written as
// "X=-200:200:10 Y=-100:100:10 Z=0 B=-90:90:30" (mm for linear axes and tip coordinates, degrees for rotary axes).
#include <string>
#include <string_view>
#include <vector>

namespace cnccomp {

struct GridAxis {
    std::string name;  ///< axis name (X, Y, Z, A, B, C, …)
    double from = 0, to = 0, step = 0;  ///< in the text's units (mm or deg); step 0 for a single value
    long count = 1;
    /// i-th value in the text's units; the last value is exactly `to` when the step divides the range.
    double value(long i) const { return i + 1 == count ? (count == 1 ? from : to) : from + step * static_cast<double>(i); }
};

struct MapGrid {
    std::vector<GridAxis> axes;  ///< in the order written; the last one varies fastest
    long size() const;           ///< number of grid points (product of the counts)
    /// Index of an axis by name, or -1.
    int find(std::string_view name) const;
    /// Per-axis index of a flat point index (mixed radix, last axis fastest); `out` has axes.size() entries.
    void unflatten(long index, long* out) const;
};

/// Parses "NAME=from:to:step" or "NAME=value" items separated by blanks or commas. Ranges must be increasing and
/// land on `to` (within 1e-9 of a step); at most `maxPoints` points. Throws InputError naming `source`.
MapGrid parseGrid(std::string_view text, const std::string& source = "--grid", long maxPoints = 200'000'000);

}  // namespace cnccomp
