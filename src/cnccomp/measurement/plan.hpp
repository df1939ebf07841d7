#pragma once
// A measurement plan: the runs to measure on one machine, of every kind. Run names are unique across all kinds (each
// run's data is DIR/<name>.csv). Read and written by io/plan_xml.hpp.
#include <limits>
#include <string>
#include <vector>

#include "cnccomp/ballbar.hpp"
#include "cnccomp/linear_circle_run.hpp"
#include "cnccomp/measurement/dbb5_run.hpp"
#include "cnccomp/measurement/rtest_run.hpp"
#include "cnccomp/measurement/sphere_run.hpp"

namespace cnccomp::measurement {

struct MeasurementPlan {
    std::string machine;      ///< machine name the plan was made for (may be empty)
    int line = 0;             ///< line of <plan> in the file it was read from (0 when not read from a file)
    std::string description;
    /// Stated noise of the instrument (one sample's standard deviation), µm: <plan noise-um="0.2">; NaN = not stated.
    /// The model-adequacy test (identification/adequacy.hpp) uses it for runs without repeated passes.
    double noiseUm = std::numeric_limits<double>::quiet_NaN();
    std::vector<BallbarRun> runs;          ///< <run>
    std::vector<BallbarRun> absoluteRuns;  ///< <absolute-run>
    std::vector<RtestRun> rtestRuns;       ///< <rtest>
    std::vector<Dbb5Run> dbb5Runs;         ///< <dbb5>
    std::vector<LinearCircleRun> circleRuns;  ///< <circle>
    std::vector<SphereRun> sphereRuns;     ///< <sphere> (touch probe on a calibration sphere)
    /// Total number of runs of every kind.
    size_t runCount() const {
        return runs.size() + absoluteRuns.size() + rtestRuns.size() + dbb5Runs.size() + circleRuns.size() +
               sphereRuns.size();
    }
};

}  // namespace cnccomp::measurement
