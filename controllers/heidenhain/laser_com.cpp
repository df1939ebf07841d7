#include "controllers/heidenhain/laser_com.hpp"

#include <fmt/format.h>

#include "controllers/common/laser_axis.hpp"
#include "controllers/heidenhain/tnc_table.hpp"

namespace cnccomp::controllers::heidenhain {

LaserCom heidenhainLaserCom(const LaserPositioningResult& r, bool referenceForward) {
    const LaserAxisCompensation c = laserAxisCompensation(r, referenceForward);
    LaserCom out;
    out.name = r.axis + ".COM";
    out.backlashMm = c.backlashUm * 1e-3;
    TncTable t;
    t.name = out.name;
    const std::string column = "E" + r.axis + r.axis;
    t.columns = {"NR", "AXISPOS", column};
    for (size_t i = 0; i < c.positions.size(); ++i)
        t.rows.push_back({std::to_string(i), fmt::format("{:.6f}", c.positions[i]), fmt::format("{:.7f}", c.referenceUm[i] * 1e-3)});
    const std::vector<std::string> notes = {
        fmt::format("cnccomp laser: positioning error of axis {} from ISO 230-2 laser runs (mm, actual - target)", r.axis),
        fmt::format("the error approached in {} (the reference-approach direction [G]); assign with COMPTAB {}:{} on the "
                    "MachAxis {} row [G]", referenceForward ? "+" : "-", out.name, column, r.axis),
        fmt::format("set MP710 (backlash compensation, mm) of axis {} to {:.6f} (= -mean reversal) [G]; one value leaves up "
                    "to {:.3f} um of the reversal at single targets", r.axis, out.backlashMm, c.backlashLeftUm),
        servoMismatchNote("MP1810 kv factor [G]"),
        "measured with the axis' compensation and backlash compensation off",
    };
    std::string comment;
    for (const std::string& n : notes) comment += "; " + n + "\n";
    out.text = formatTncTable(t, comment);
    return out;
}

}  // namespace cnccomp::controllers::heidenhain
