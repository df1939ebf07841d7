#include "cnccomp/io/linear_circle_trace.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/csv.hpp"
#include "cnccomp/io/text_util.hpp"
#include "cnccomp/io/trace_export.hpp"

namespace cnccomp::io {

// Internals in a named namespace (not anonymous): the core may be compiled as unity units.
namespace linear_circle_trace_detail {

std::string lcOneLine(std::string s) {
    for (char& c : s)
        if (c == '\n' || c == '\r') c = ' ';
    return s;
}

std::string lcLower(std::string s) {
    for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return s;
}

}  // namespace linear_circle_trace_detail

BallbarRun linearCircleImportRun(const LinearCircleRun& run) {
    BallbarRun b;
    b.name = run.name;
    b.test = BallbarTest::CZ;  // not written into circle files; only the geometry below is used
    b.LB = run.radius;
    b.RB = run.radius;
    b.RC = run.radius;
    b.ZC = 0;
    b.startDeg = run.startDeg;
    b.endDeg = run.endDeg();
    b.stepDeg = run.stepDeg;
    b.capture = run.capture;
    if (b.capture.passes.empty()) b.capture.passes = run.directions();
    b.capture.feedRadius = run.radius;  // the feed is the contouring feed on the circle
    return b;
}

LinearCircleTrace importLinearCircleTrace(const std::string& path, const LinearCircleRun& run, const std::string& machine) {
    using namespace linear_circle_trace_detail;
    LinearCircleTrace out;
    // The circle's own metadata first (a file of another circle is named as such before its samples are judged).
    {
        CsvReader reader(path);
        reader.header();
        CsvRow row;
        while (reader.next(row)) {
        }
        for (const CsvComment& c : reader.comments()) {
            const std::string key = lcLower(c.key);
            const auto mismatch = [&](const std::string& planned) {
                throw InputError(path, c.line, fmt::format("the file says {} '{}', but circle run '{}' of the plan has {}: "
                                                           "this file belongs to another run or setup",
                                                           c.key, c.value, run.name, planned));
            };
            const auto number = [&](double planned) {
                const auto v = parseNumber(c.value);
                if (!v) throw InputError(path, c.line, fmt::format("'{}: {}' is not a number", c.key, c.value));
                if (std::abs(*v - planned) > 1e-6 * std::max(1.0, std::abs(planned))) mismatch(fmt::format("{:g}", planned));
            };
            if (key == "plane") {
                if (c.value != linearPlaneName(run.plane)) mismatch(linearPlaneName(run.plane));
            } else if (key == "radius") {
                number(run.radius);
            } else if (key == "arc") {
                number(run.arcDeg);
            } else if (key == "date") {
                out.date = c.value;
            } else if (key == "instrument") {
                out.instrument = c.value;
            } else if (key == "operator") {
                out.operatorName = c.value;
            }
        }
    }
    // run, machine, LB (= radius), start, end, step and feed are checked by the ball-bar import.
    out.measured = importRunTrace(path, linearCircleImportRun(run), machine);
    return out;
}

std::string formatLinearCircleTrace(const LinearCircleRun& run, const std::vector<DirectedTrace>& passes, bool timeSampled,
                                    const std::string& machine) {
    using namespace linear_circle_trace_detail;
    const RunCapture& c = run.capture;
    const double omegaDeg = c.feed / 60.0 / run.radius * 180.0 / kPi;  // deg/s
    if (timeSampled && !(omegaDeg > 0)) throw ModelError(fmt::format("circle run '{}': a time-sampled file needs the feed", run.name));
    std::string o = "# cnccomp ball-bar circle of the linear axes (ISO 230-4)\n";
    o += fmt::format("# run: {}\n", lcOneLine(run.name));
    if (!machine.empty()) o += fmt::format("# machine: {}\n", lcOneLine(machine));
    o += fmt::format("# plane: {}\n# radius: {:g}\n# start: {:g}\n# arc: {:g}\n# end: {:g}\n# step: {:g}\n# feed: {:g}\n",
                     linearPlaneName(run.plane), run.radius, run.startDeg, run.arcDeg, run.endDeg(), run.stepDeg, c.feed);
    for (const auto& [key, value] : {std::pair<const char*, const std::string*>{"date", &run.date},
                                     {"instrument", &run.instrument}, {"operator", &run.operatorName}})
        if (!value->empty()) o += fmt::format("# {}: {}\n", key, lcOneLine(*value));
    appendCapturedPasses(o, c, passes, timeSampled, omegaDeg);
    return o;
}

}  // namespace cnccomp::io
