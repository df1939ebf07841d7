#include "controllers/fanuc/laser_pitch.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "controllers/common/laser_axis.hpp"
#include "controllers/fanuc/parameter_file.hpp"

namespace cnccomp::controllers::fanuc {
using namespace cnccomp::controllers::common;

long backlashDetectionUnits(double backlashUm, double unitMm) { return std::lround(backlashUm * 1e-3 / unitMm); }

void addBacklashParameters(std::vector<Parameter>& lines, const std::map<int, long>& units) {
    if (units.empty()) return;
    for (int number : {1851, 1852}) {
        Parameter p;
        p.number = number;
        p.kind = 'A';
        for (const auto& [axis, value] : units) p.values[axis] = std::to_string(value);
        lines.push_back(p);
    }
}

LaserPitch fanucLaserPitch(const LaserPositioningResult& r, int axisNumber, bool referenceForward, const PitchOptions& o) {
    const LaserAxisCompensation c = laserAxisCompensation(r, referenceForward);
    const double first = c.positions.front(), last = c.positions.back();
    const double interval = std::max(0.1, std::round((last - first) / (static_cast<double>(c.positions.size()) - 1) * 10) / 10);
    // Boundaries k·interval from below the first target (or 0) to above the last (or 0).
    const long kLo = std::min(0L, static_cast<long>(std::floor(first / interval + 1e-9)));
    const long kHi = std::max(0L, static_cast<long>(std::ceil(last / interval - 1e-9)));
    const int nb = static_cast<int>(kHi - kLo + 1);
    if (nb - 1 > o.maxIntervals)
        throw ModelError(fmt::format("fanuc-30i: {} intervals of {:g} mm; the control holds {} per axis", nb - 1, interval,
                                     o.maxIntervals));
    const int rIndex = static_cast<int>(-kLo);  // boundary at machine 0
    const double e0 = r.errorAt(0.0, referenceForward);
    std::vector<double> corr(static_cast<size_t>(nb));  // mm
    for (int k = 0; k < nb; ++k) corr[static_cast<size_t>(k)] = -(r.errorAt((kLo + k) * interval, referenceForward) - e0) * 1e-3;
    LaserPitch out;
    PitchTable& t = out.table;
    t.interval = interval;
    t.reference = std::max(rIndex - 1, 0);
    t.negative = t.reference - rIndex + 1;
    t.positive = t.negative + nb - 2;
    double maxStep = 0;
    for (int k = 1; k < nb; ++k) maxStep = std::max(maxStep, std::abs(corr[static_cast<size_t>(k)] - corr[static_cast<size_t>(k - 1)]) / o.unit);
    for (t.magnification = std::max(1, static_cast<int>(std::ceil(maxStep / o.maxData)));; ++t.magnification) {
        if (t.magnification > o.maxMagnification)
            throw ModelError(fmt::format("fanuc-30i: the pitch error changes by {:.1f} detection units per interval", maxStep));
        const double u = o.unit * t.magnification;
        t.data.assign(static_cast<size_t>(nb - 1), 0);
        bool fits = true;
        for (int s = 0; s + 1 < nb; ++s) {
            const long v = std::lround(corr[static_cast<size_t>(s + 1)] / u) - std::lround(corr[static_cast<size_t>(s)] / u);
            t.data[static_cast<size_t>(s)] = v;
            fits = fits && std::abs(v) <= o.maxData;
        }
        if (fits) break;
    }
    out.backlash = backlashDetectionUnits(c.backlashUm, o.unit);

    std::vector<Parameter> lines;
    const auto axisParam = [&](int number, const std::string& value) {
        Parameter p;
        p.number = number;
        p.kind = 'A';
        p.values[axisNumber] = value;
        lines.push_back(p);
    };
    addBacklashParameters(lines, {{axisNumber, out.backlash}});
    axisParam(3620, std::to_string(t.reference));
    axisParam(3621, std::to_string(t.negative));
    axisParam(3622, std::to_string(t.positive));
    axisParam(3623, std::to_string(t.magnification));
    axisParam(3624, decimal(t.interval, 4));
    axisParam(3625, "0.0");
    for (int k = t.negative; k <= t.positive; ++k) {
        Parameter d;
        d.number = 10000 + k;
        d.q = 0;
        d.values[0] = std::to_string(t.data[static_cast<size_t>(k - t.negative)]);
        lines.push_back(d);
    }
    const std::vector<std::string> notes = {
        fmt::format("cnccomp laser: pitch error and backlash of axis {} (A{}) from ISO 230-2 laser runs", r.axis, axisNumber),
        fmt::format("table: the error approached in {} (the reference return direction, 1006#5 ZMI = {} [G]), resampled "
                    "every {:g} mm from the reference position (machine 0), correction = -(error - error at 0)",
                    referenceForward ? "+" : "-", referenceForward ? 0 : 1, interval),
        fmt::format("error at the reference position {:.3f} um: a shift of the reference position (1850, by hand), not "
                    "in the table", e0),
        fmt::format("1851/1852 backlash {} detection units = {:.3f} um (= -mean reversal); one value leaves up to {:.3f} um "
                    "of the reversal at single targets", out.backlash, c.backlashUm, c.backlashLeftUm),
        "detection unit IS-C 0.0001 mm [G]; pitch data sign: correction added to the command [G]; point numbers from 0 "
        "(renumber if they overlap another axis' table) [G]",
        servoMismatchNote("parameter 1825, servo loop gain per axis [G]"),
        "measured with the axis' pitch and backlash compensation off; power off/on and a reference return after loading",
    };
    std::string header;
    for (std::string n : notes) {  // a parenthesis inside would end the comment early: brackets instead
        std::replace(n.begin(), n.end(), '(', '[');
        std::replace(n.begin(), n.end(), ')', ']');
        header += "(" + n + ")\n";
    }
    out.file = formatParameterFile(header, lines);
    return out;
}

}  // namespace cnccomp::controllers::fanuc
