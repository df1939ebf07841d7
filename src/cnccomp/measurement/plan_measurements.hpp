#pragma once
// Every capture of one measurement plan, read once from the folder of the measured runs (io/plan_measurements_io.hpp
// reads it), then handed to the identification: ball-bar traces with their import summary, absolute ball-bar traces,
// R-test poses, DBB5 traces, circles of the linear axes, the probe result file. Before this object the
// identification read the folder itself, and a method could read one file twice (the R-test and DBB5 methods read
// their runs, then least squares read them again through the observations).
//
// The capture types still live beside their readers or their observations (MeasuredTrace in io/trace_import.hpp,
// LinearCircleTrace in io/linear_circle_trace.hpp, RtestTrace in identification/rtest_run.hpp); moving them into
// measurement/ is a step not yet taken.
#include <optional>
#include <string>
#include <vector>

#include "cnccomp/ballbar.hpp"
#include "cnccomp/identification/rtest_run.hpp"
#include "cnccomp/io/linear_circle_trace.hpp"
#include "cnccomp/io/trace_import.hpp"
#include "cnccomp/measurement/probe_log.hpp"

namespace cnccomp::measurement {

/// Which kinds of runs of a plan to read (a method reads only the runs it uses).
struct MeasurementKinds {
    bool ballbar = false;   ///< <run>: imported and checked against their runs and the machine's name
    bool absolute = false;  ///< <absolute-run>
    bool rtest = false;     ///< <rtest>
    bool dbb5 = false;      ///< <dbb5>
    bool circles = false;   ///< <circle>
    bool probes = false;    ///< the probe result file of the <sphere> runs
    /// The runs every least-squares observation of a plan reads (identification/measured_observations.hpp).
    static MeasurementKinds observed() { return {true, true, true, true, false, false}; }
};

struct PlanMeasurements {
    std::string folder;                       ///< where they were read from
    MeasurementKinds loaded;                  ///< which kinds were read
    std::vector<io::MeasuredTrace> ballbar;       ///< one per plan.runs entry, same order
    std::vector<BallbarTrace> absolute;       ///< one per plan.absoluteRuns entry
    std::vector<identification::RtestTrace> rtest;            ///< one per plan.rtestRuns entry
    std::vector<BallbarTrace> dbb5;           ///< one per plan.dbb5Runs entry
    std::vector<io::LinearCircleTrace> circles;   ///< one per plan.circleRuns entry
    std::optional<ProbeLog> probes;           ///< the <sphere> runs' probe result file
};

}  // namespace cnccomp::measurement
