#pragma once
// The identification route of a plan of ball-bar circles of the linear axes (<circle> runs): every run's
// instrument file imported (io/linear_circle_trace.hpp), its passes evaluated after ISO 230-4 (circular_test.hpp:
// G per pass, F, hysteresis H) and its diagnostics identified on the exact model (linear_circle_model.hpp: value,
// 95 % interval, share of the circularity, ranked; unidentified ones with their confounded groups), headed by the
// test conditions. The squareness of each plane is also written into the machine's deviation set under its ISO
// 230-1 name when the machine has it (XY → EC0Y or EC0X, YZ → EA0Z or EA0Y, ZX → EB0Z or EB0X: the rotation of the
// downstream slide of the pair in the machine's chain): value = squareness / s, with s the
// squareness the same circle identifies on the nominal machine with that deviation at 1″ (the machine's own
// kinematics give the sign and the scale, table-moving axes included). Several circles of one plane are combined
// by inverse variance. The backlash steps of each axis go in as its reversal value (LinearCircleReversal). Nothing else
// of the diagnostics has a place in the deviation set: they are reported.
#include <limits>
#include <string>
#include <vector>

#include "cnccomp/circular_test.hpp"
#include "cnccomp/deviations.hpp"
#include "cnccomp/io/linear_circle_trace.hpp"
#include "cnccomp/io/trace_import.hpp"
#include "cnccomp/linear_circle_model.hpp"
#include "cnccomp/linear_circle_run.hpp"

namespace cnccomp {

/// The test conditions of a run, as the plan and the file give them (ISO 230-4 clause 6 asks for them in the report).
struct LinearCircleConditions {
    std::string file, layout;          ///< the instrument file; "angle" or "time" sampled
    LinearPlane plane = LinearPlane::XY;
    Vec3 centre = Vec3::Zero();        ///< mm, commands
    double radius = 0, startDeg = 0, arcDeg = 0, feed = 0, overshootDeg = 0, toolLength = 0;
    std::vector<int> directions;
    std::vector<int> samples;          ///< per pass, inside the data arc
    double spacingDeg = 0;             ///< mean angular spacing of the samples
    double sampleRateHz = std::numeric_limits<double>::quiet_NaN();  ///< time-sampled files: samples per second
    double feedFromData = 0;           ///< time-sampled files: the feed the passes' durations give (0: not known)
    std::string date, instrument, operatorName;  ///< the file's own lines first, else the plan's
    /// The instrument reads the length relative to an unknown zero (length="relative"): the radius offset takes the
    /// zero up, G and H keep their meaning, F max / F min and the mean radius are relative to that zero.
    bool relativeLength = false;
};

struct LinearCircleRunResult {
    std::string run;
    LinearCircleConditions conditions;
    LinearCircle circle;
    std::vector<LinearCirclePass> passes;
    LinearCircleFit fit;
    CircularRunResult iso;                    ///< ISO 230-4 figures of the passes as measured
    std::vector<std::vector<double>> after;   ///< per pass: ΔL with the identified diagnostics removed, mm
    io::TraceImportSummary summary;
};

/// A deviation of the set written from the circles.
struct LinearCircleDeviation {
    std::string name;          ///< ISO name (EC0Y, EA0Z, EB0Z, or EC0X, EA0Y, EB0X)
    double value = 0, stddev = 0, lower95 = 0, upper95 = 0;  ///< arcsec (ISO value)
    double perArcsec = 0;      ///< squareness (µm/m) the circle sees per arcsec of the deviation
    std::vector<std::string> runs;
};

/// A reversal value of the set written from the circles' backlash (DeviationSet::reversal): B = −b, with b the
/// inverse-variance mean of the identified backlash steps of the axis (both ends, every circle that has the axis).
/// Why −b: the circle model's step b_{u+} (linear_circle_model.hpp) is the jump of the axis' actual position in its
/// command coordinate when it reverses from + to − at the + end (b > 0: it lags its command), so after the reversal
/// the positional deviation x = actual − command is b higher than before: x̄↓ − x̄↑ = b_{u+}, i.e. ISO 230-2's
/// B = x̄↑ − x̄↓ = −b_{u+}; at the − end (− to +, u_a −= b_{u−}) likewise B = −b_{u−}. The circle's commands are the
/// axes' commands (linear_circle_run.hpp) and the bar reads the tool relative to the workpiece, as the laser does, so
/// the value is in the laser's frame with no sign from the kinematics. A difference b_{u+} − b_{u−} (a reversal that
/// depends on the position) has no place in one value: it is in the note.
struct LinearCircleReversal {
    std::string axis;          ///< X, Y or Z; the set's row is B<axis>
    double value = 0, stddev = 0, lower95 = 0, upper95 = 0;  ///< µm (B = −b)
    std::vector<std::string> from;  ///< "run: backlash X+" of every step combined
};

struct LinearCircleIdentification {
    std::vector<LinearCircleRunResult> runs;
    DeviationSet deviations;
    std::vector<LinearCircleDeviation> written;
    std::vector<LinearCircleReversal> reversals;
    std::vector<std::string> notes;  ///< what was not written into the deviation set, and why
};

/// Imports DIR/<run>.csv of every run and identifies. InputError naming the file for a file that does not fit its
/// run; ModelError for a machine that cannot make a run.
LinearCircleIdentification identifyLinearCircleRuns(const MachineModel& machine, const std::vector<LinearCircleRun>& runs,
                                                    const std::string& tracesDir, const LinearCircleSettings& settings = {});
/// The same on the runs' files already read (PlanMeasurements::circles, io/plan_measurements_io.hpp: each run validated
/// and its commands checked against the machine before its file was read), one per run in order.
LinearCircleIdentification identifyLinearCircleRuns(const MachineModel& machine, const std::vector<LinearCircleRun>& runs,
                                                    const std::vector<io::LinearCircleTrace>& files,
                                                    const LinearCircleSettings& settings = {});

}  // namespace cnccomp
