#include "controllers/common/axis_table.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "cnccomp/error.hpp"

namespace cnccomp::controllers::common {

double EquidistantTable::at(double x) const {
    const int n = static_cast<int>(values.size());
    if (n == 0) return 0.0;
    if (n == 1) return values[0];
    if (modulo) {
        const double period = max() - min;
        x = std::fmod(x - min, period);
        if (x < 0) x += period;
        x += min;
    }
    if (x <= min) return values.front();
    if (x >= max()) return values.back();
    const double u = (x - min) / step;
    const int i = std::min(static_cast<int>(std::floor(u)), n - 2);
    const double f = u - i;
    return values[i] + (values[i + 1] - values[i]) * f;
}

double niceStepAtLeast(double x) {
    if (!(x > 0) || !std::isfinite(x)) throw ModelError("table step must be a positive finite number");
    const double p = std::pow(10.0, std::floor(std::log10(x)));
    for (double m : {1.0, 2.0, 2.5, 5.0, 10.0})
        if (m * p >= x * (1 - 1e-12)) return m * p;
    return 10 * p;
}

double positionScale(const Link& axis) { return axis.kind == AxisKind::Rotary ? 1.0 / kDeg : 1.0; }

double commandOf(const Link& axis, double filePosition) { return filePosition / positionScale(axis) + axis.machineZero; }

EquidistantTable gridOverTravel(const Link& axis, int maxPoints) {
    if (maxPoints < 2) throw ModelError("a compensation table needs at least two points");
    EquidistantTable t;
    if (axis.kind == AxisKind::Rotary && axis.modulo) {
        // Steps dividing 360°, finest first.
        static constexpr double kDivisors[] = {0.5, 1, 1.5, 2, 2.5, 3, 4, 5, 6, 7.5, 8, 9, 10, 12, 15, 18, 20,
                                               22.5, 24, 30, 36, 40, 45, 60, 72, 90, 120, 180};
        for (double s : kDivisors)
            if (360.0 / s + 1 <= maxPoints + 1e-9) {
                t.min = 0;
                t.step = s;
                t.modulo = true;
                t.values.assign(static_cast<size_t>(std::lround(360.0 / s)) + 1, 0.0);
                return t;
            }
        throw ModelError(fmt::format("a table over modulo axis {} needs more than {} points", axis.name, maxPoints));
    }
    const double scale = positionScale(axis);
    const double lo = std::min((axis.min - axis.machineZero) * scale, 0.0);
    const double hi = std::max((axis.max - axis.machineZero) * scale, 0.0);
    if (!std::isfinite(lo) || !std::isfinite(hi))
        throw ModelError(fmt::format("axis {} has no finite travel; a compensation table needs one (set min and max)",
                                     axis.name));
    if (hi - lo <= 0) throw ModelError(fmt::format("axis {} has no travel to tabulate", axis.name));
    double step = niceStepAtLeast((hi - lo) / (maxPoints - 1));
    for (;;) {
        const double a = std::floor(lo / step + 1e-9) * step, b = std::ceil(hi / step - 1e-9) * step;
        const long n = std::lround((b - a) / step) + 1;
        if (n <= maxPoints) {
            t.min = a;
            t.step = step;
            t.values.assign(static_cast<size_t>(n), 0.0);
            return t;
        }
        step = niceStepAtLeast(step * 1.0001);
    }
}

}  // namespace cnccomp::controllers::common
