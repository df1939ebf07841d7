#include "controllers/heidenhain/laser_com.hpp"

#include <fmt/format.h>

#include "controllers/common/laser_axis.hpp"
#include "controllers/heidenhain/tnc_table.hpp"

namespace cnccomp::controllers::heidenhain {
using namespace cnccomp::controllers::common;

int tncAxisIndex(const std::string& axisName) {
    return axisName == "X" ? 0 : axisName == "Y" ? 1 : axisName == "Z" ? 2 : -1;
}

std::string mp710Line(int index, double backlashMm) { return fmt::format("MP710.{}:{:+.6f}", index, backlashMm); }

LaserCom heidenhainLaserCom(const LaserPositioningResult& r, int column, double sign, bool referenceForward) {
    const LaserAxisCompensation c = laserAxisCompensation(r, referenceForward);
    LaserCom out;
    out.name = r.axis + ".COM";
    out.backlashMm = c.backlashUm * 1e-3;
    TncTable t;
    t.name = out.name;
    const std::string columnName = fmt::format("C{}", column);
    t.columns = {"NR", "AXISPOS", columnName};
    for (size_t i = 0; i < c.positions.size(); ++i)
        t.rows.push_back({std::to_string(i), fmt::format("{:.6f}", c.positions[i]), fmt::format("{:.9f}", sign * c.referenceUm[i] * 1e-3)});
    const std::vector<std::string> notes = {
        fmt::format("cnccomp laser: positioning error of axis {} from ISO 230-2 laser runs (mm, actual - target)", r.axis),
        fmt::format("the error approached in {} (the reference-approach direction [G]) as the column of its positioning "
                    "component, with the sign cnccomp emit gives it ({:+g} x the laser's error); COMPTAB {}:{} on the "
                    "MachAxis {} row", referenceForward ? "+" : "-", sign, out.name, columnName, r.axis),
        fmt::format("set MP710 (backlash compensation, mm) of axis {} to {:.6f} (= -mean reversal; {}); one value leaves up "
                    "to {:.3f} um of the reversal at single targets", r.axis, out.backlashMm,
                    tncAxisIndex(r.axis) >= 0 ? mp710Line(tncAxisIndex(r.axis), out.backlashMm) : std::string("MP710.x"),
                    c.backlashLeftUm),
        servoMismatchNote("MP1810 kv factor [G]"),
        "measured with the axis' compensation and backlash compensation off",
    };
    std::string comment;
    for (const std::string& n : notes) comment += "; " + n + "\n";
    out.text = formatTncTable(t, comment);
    return out;
}

}  // namespace cnccomp::controllers::heidenhain
