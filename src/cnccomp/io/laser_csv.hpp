#pragma once
// Import of a laser interferometer's bidirectional positioning runs of one linear axis (ISO 230-2:2014, evaluated by
// evaluateLaserPositioning, cnccomp/laser_positioning.hpp). Layout (one row per reading, any row order; read with
// the one CSV reader, io/csv.hpp: UTF-8 BOM, ',' ';' or tab, a decimal comma with ';' or tab, '#' comments):
//
//   # axis: X                         (optional; --axis gives it when the file does not)
//   # environment-compensated: yes    (optional, yes|no: the laser's air / material temperature compensation was
//                                      applied to the readings; absent = not stated, evaluated as not done)
//   target_mm,run,direction,deviation_um
//   0,1,+,0.4
//   0,1,-,-2.6
//   ...
//
//  - target_mm: the target position P_i, mm (rows of the same target must give the same number);
//  - run: a label for the run j (a number or a name); the forward and the reverse runs are counted separately and
//    kept in the order they first appear;
//  - direction: '+' / '-', 'fwd' / 'rev', 'forward' / 'reverse' (case-insensitive): the approach direction
//    (↑ positive, ↓ negative);
//  - deviation: x_ij = P_ij − P_i (actual minus target, ISO 230-2 clause 2), in µm (or mm with unit "mm").
// Column names and the deviation unit are options (LaserCsvOptions). Every run must give exactly one reading at
// every target; the minimum counts of ISO 230-2 4.3.2 are checked by the evaluation (with the file's name).
#include <string>
#include <string_view>

#include "cnccomp/laser_positioning.hpp"

namespace cnccomp::io {

struct LaserCsvOptions {
    std::string targetColumn = "target_mm";
    std::string runColumn = "run";
    std::string directionColumn = "direction";
    std::string deviationColumn;      ///< empty: "deviation_um" or "deviation_mm" after deviationUnit
    std::string deviationUnit = "um"; ///< "um" or "mm"
    std::string axis;                 ///< empty: the file's "# axis:"; both given and different is an error
};

struct LaserCsvFile {
    LaserPositioningRuns runs;        ///< source = the file's path
    bool environmentStated = false;   ///< the file has "# environment-compensated: yes|no"
};

/// Throws InputError (file:line, what was expected) for: a missing column, a number cell that is not a number, an
/// unknown direction label, a reading given twice (run, direction, target), a run missing a target, a bad
/// "# environment-compensated:" value, a missing or conflicting axis name, a unit other than um|mm.
LaserCsvFile readLaserCsv(const std::string& path, const LaserCsvOptions& options = {});
/// The same from text in memory (`name` for messages).
LaserCsvFile parseLaserCsv(std::string_view text, const std::string& name, const LaserCsvOptions& options = {});

}  // namespace cnccomp::io
