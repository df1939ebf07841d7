#include "cnccomp/io/trace_csv.hpp"

#include <ostream>

#include <fmt/format.h>

#include "cnccomp/io/text_util.hpp"
#include "cnccomp/io/trace_import.hpp"

namespace cnccomp::io {

namespace {
/// Metadata values stay on their line.
std::string oneLine(std::string s) {
    for (char& c : s)
        if (c == '\n' || c == '\r') c = ' ';
    return s;
}
}  // namespace

BallbarTrace readTraceCsv(const std::string& path) { return importTrace(path).trace; }

std::string formatTraceCsv(const BallbarTrace& trace, const BallbarRun* run, const std::string& machine) {
    std::string o;
    if (run) {
        o += "# cnccomp ball-bar trace (angle in deg, dL = L - LB in um; lengths in mm)\n";
        o += fmt::format("# run: {}\n# test: {}\n", oneLine(run->name), testName(run->test));
        if (!machine.empty()) o += fmt::format("# machine: {}\n", oneLine(machine));
        o += fmt::format("# LB: {:g}\n# RB: {:g}\n# RC: {:g}\n# ZC: {:g}\n# start: {:g}\n# end: {:g}\n# step: {:g}\n", run->LB,
                         run->RB, run->RC, run->ZC, run->startDeg, run->endDeg, run->stepDeg);
        if (run->capture.feed > 0) o += fmt::format("# feed: {:g}\n", run->capture.feed);
    }
    o += "angle_deg,dL_um\n";
    for (size_t i = 0; i < trace.dL.size(); ++i) o += fmt::format("{:.6f},{:.6f}\n", trace.angleDeg[i], trace.dL[i] / kUm);
    return o;
}

void writeTraceCsv(const std::string& path, const BallbarTrace& trace) {
    const std::string text = formatTraceCsv(trace);
    writeFileAtomically(path, [&](std::ostream& o) { o << text; });
}

void writeTraceCsv(const std::string& path, const BallbarTrace& trace, const BallbarRun& run, const std::string& machine) {
    const std::string text = formatTraceCsv(trace, &run, machine);
    writeFileAtomically(path, [&](std::ostream& o) { o << text; });
}

}  // namespace cnccomp::io

namespace cnccomp::io {
std::vector<BallbarTrace> readRunTraces(const std::string& dir, const std::vector<BallbarRun>& runs) {
    std::vector<BallbarTrace> out;
    for (MeasuredTrace& m : importRunTraces(dir, runs)) out.push_back(std::move(m.trace));
    return out;
}
}  // namespace cnccomp::io
