#include "cli/print.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace cnccomp::cli {

std::pair<double, double> printDeviations(const DeviationSet& d, const DeviationSet* truth) {
    const MachineModel& m = d.machine();
    double maxLen = 0, maxAng = 0;
    if (truth)
        fmt::print("{:<8} {:<6} {:>12} {:>12} {:>10}  {}   (ISO values)\n", "name", "alias", "identified", "truth", "diff", "unit");
    else
        fmt::print("{:<8} {:<6} {:>12}  {}   (ISO values)\n", "name", "alias", "value", "unit");
    for (size_t i = 0; i < m.deviations.size(); ++i) {
        const DeviationDef& def = m.deviations[i];
        if (!d.present[i] || def.kind != DeviationKind::Location) continue;
        const double scale = def.isAngle() ? 1.0 / kArcsec : 1.0 / kUm;
        const char* unit = def.isAngle() ? "arcsec" : "um";
        const double v = d.isoValue(static_cast<int>(i)) * scale;  // the value under the ISO name
        if (truth) {
            const double t = truth->isoValue(static_cast<int>(i)) * scale;
            (def.isAngle() ? maxAng : maxLen) = std::max(def.isAngle() ? maxAng : maxLen, std::abs(v - t));
            fmt::print("{:<8} {:<6} {:12.4f} {:12.4f} {:10.4f}  {}\n", def.name, def.alias, v, t, v - t, unit);
        } else {
            fmt::print("{:<8} {:<6} {:12.4f}  {}\n", def.name, def.alias, v, unit);
        }
    }
    return {maxLen, maxAng};
}

}  // namespace cnccomp::cli
