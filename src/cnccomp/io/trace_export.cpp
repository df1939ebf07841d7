#include "cnccomp/io/trace_export.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/trace_csv.hpp"
#include "cnccomp/io/trace_import.hpp"

namespace cnccomp::io {

std::vector<DirectedTrace> simulateCapturedPasses(const Kinematics& k, const BallbarRun& run) {
    const std::vector<int> directions = run.capture.passes.empty() ? std::vector<int>{run.stepDeg < 0 ? -1 : +1}
                                                                   : run.capture.passes;
    const double lo = std::min(run.startDeg, run.endDeg), hi = std::max(run.startDeg, run.endDeg);
    const double ov = run.capture.overshootDeg, step = std::abs(run.stepDeg);
    std::vector<DirectedTrace> out;
    for (const int d : directions) {
        BallbarRun sweep = run;
        sweep.capture = {};
        sweep.startDeg = d > 0 ? lo - ov : hi + ov;
        sweep.endDeg = d > 0 ? hi + ov : lo - ov;
        sweep.stepDeg = d * step;
        // An instrument records both ends of a whole turn: simulate the closing sample too.
        BallbarTrace t = simulateRun(k, sweep);
        if (std::abs(t.angleDeg.back() - sweep.endDeg) > 1e-9 * std::max(1.0, std::abs(sweep.endDeg)) &&
            std::abs(std::remainder(sweep.endDeg - t.angleDeg.back(), step)) < 1e-9) {
            BallbarRun last = sweep;
            last.startDeg = last.endDeg;
            last.stepDeg = d;
            const BallbarTrace e = simulateRun(k, last);
            t.angleDeg.push_back(sweep.endDeg);
            t.dL.push_back(e.dL.front());
        }
        out.push_back({d, std::move(t)});
    }
    return out;
}

void appendCapturedPasses(std::string& o, const RunCapture& c, const std::vector<DirectedTrace>& passes, bool timeSampled,
                          double omegaDeg) {
    const char sep = c.decimal == ',' ? ';' : ',';
    const auto number = [&](double v, int decimals) {
        std::string s = fmt::format("{:.{}f}", v, decimals);
        if (c.decimal == ',') std::replace(s.begin(), s.end(), '.', ',');
        return s;
    };
    o += fmt::format("{}{}{}", timeSampled ? c.timeColumn : c.angleColumn, sep, c.lengthColumn);
    if (passes.size() > 1) o += fmt::format("{}{}", sep, c.passColumn);
    o += "\n";
    double t0 = 0;
    for (const DirectedTrace& p : passes) {
        if (p.trace.dL.empty()) continue;
        const double a0 = p.trace.angleDeg.front();
        for (size_t i = 0; i < p.trace.dL.size(); ++i) {
            const double x = timeSampled ? (t0 + std::abs(p.trace.angleDeg[i] - a0) / omegaDeg) / c.timeUnit
                                         : p.trace.angleDeg[i] / c.angleUnit;
            o += number(x, 7) + sep + number(p.trace.dL[i] / c.lengthUnit, c.lengthUnit >= 1.0 ? 10 : 7);
            if (passes.size() > 1) o += fmt::format("{}{}", sep, p.direction > 0 ? "ccw" : "cw");
            o += "\n";
        }
        if (timeSampled) t0 += std::abs(p.trace.angleDeg.back() - a0) / omegaDeg + 1.0;  // 1 s dwell between the passes
    }
}

std::string formatCapturedTrace(const BallbarRun& run, const std::vector<DirectedTrace>& passes, bool timeSampled,
                                const std::string& machine) {
    const RunCapture& c = run.capture;
    double omegaDeg = 0;
    if (timeSampled) {
        const double radius = c.feedRadius > 0 ? c.feedRadius : linearPathRadius(run);
        if (!(c.feed > 0) || !(radius > 0))
            throw ModelError(fmt::format("run '{}': a time-sampled file needs feed (and a non-zero feed radius)", run.name));
        omegaDeg = c.feed / 60.0 / radius * 180.0 / M_PI;
    }
    // Metadata and header: cnccomp's own lines, then the capture's columns and the passes.
    std::string o = formatTraceCsv(BallbarTrace{}, &run, machine);
    o.resize(o.rfind("angle_deg,dL_um\n"));
    appendCapturedPasses(o, c, passes, timeSampled, omegaDeg);
    return o;
}

}  // namespace cnccomp::io
