#include "controllers/siemens/laser_eec.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "controllers/common/laser_axis.hpp"

namespace cnccomp::controllers::siemens {
using namespace cnccomp::controllers::common;

std::string backlashMachineData(const std::string& axis, double backlashMm) {
    return fmt::format("$MA_BACKLASH[0,{}]={:.6f}\n", axis, backlashMm);
}

LaserEec siemensLaserEec(const LaserPositioningResult& r, const std::string& axis, bool referenceForward, int maxPoints) {
    const LaserAxisCompensation c = laserAxisCompensation(r, referenceForward);
    LaserEec out;
    const double first = c.positions.front(), last = c.positions.back();
    out.min = first;
    out.step = std::max(0.1, std::round((last - first) / (static_cast<double>(c.positions.size()) - 1) * 10) / 10);
    const int n = static_cast<int>(std::ceil((last - first) / out.step - 1e-9)) + 1;
    if (n > maxPoints) throw ModelError(fmt::format("siemens-840d: {} EEC points; the table holds {} [G]", n, maxPoints));
    for (int k = 0; k < n; ++k) out.values.push_back(r.errorAt(out.min + k * out.step, referenceForward) * 1e-3);
    out.backlashMm = c.backlashUm * 1e-3;

    const std::vector<std::string> notes = {
        fmt::format("cnccomp laser: leadscrew error (EEC) of axis {} ({}) from ISO 230-2 laser runs", r.axis, axis),
        fmt::format("values: the positioning error (mm) approached in {} (the direction of the reference point approach "
                    "[G]); a positive value moves the axis negative (K3)", referenceForward ? "+" : "-"),
        "load with MD32700 ENC_COMP_ENABLE = 0, then load AX_LASER_MD.INI (ENC_COMP_ENABLE = 1, BACKLASH) and reference the axis",
        fmt::format("MD32450 BACKLASH {:.6f} mm = -mean reversal; one value leaves up to {:.3f} um of the reversal at single "
                    "targets", out.backlashMm, c.backlashLeftUm),
        servoMismatchNote("MD32200 POSCTRL_GAIN [G]"),
        "measured with the axis' EEC and backlash compensation off",
    };
    std::string header;
    for (const std::string& l : notes) header += "; " + l + "\n";
    out.eec = "%_N_AX_EEC_INI\n" + header;
    for (size_t k = 0; k < out.values.size(); ++k) out.eec += fmt::format("$AA_ENC_COMP[0,{},{}]={:.6f}\n", k, axis, out.values[k]);
    out.eec += fmt::format("$AA_ENC_COMP_STEP[0,{0}]={1:.6f}\n$AA_ENC_COMP_MIN[0,{0}]={2:.6f}\n$AA_ENC_COMP_MAX[0,{0}]={3:.6f}\n"
                           "$AA_ENC_COMP_IS_MODULO[0,{0}]=0\nM17\n",
                           axis, out.step, out.min, out.min + out.step * (n - 1));
    out.machineData = "%_N_AX_LASER_MD_INI\n" + header +
                      backlashMachineData(axis, out.backlashMm) + fmt::format("$MA_ENC_COMP_ENABLE[0,{}]=1\nM17\n", axis);
    return out;
}

}  // namespace cnccomp::controllers::siemens
