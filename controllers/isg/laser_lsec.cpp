#include "controllers/isg/laser_lsec.hpp"

#include <cmath>

#include <fmt/format.h>

#include "cnccomp/error.hpp"

#include "controllers/common/laser_axis.hpp"

namespace cnccomp::controllers::isg {
using namespace cnccomp::controllers::common;

std::string isgAxisHead(int axisNumber, const std::string& axisName) {
    return fmt::format("kopf.achs_nr                        {}\nkopf.log_achs_name                  {}\n", axisNumber, axisName);
}

std::string isgAxisBacklash(int axisNumber, const std::string& axisName, double backlashUm) {
    const long tenth = std::lround(backlashUm * 10.0);
    if (std::abs(tenth) > 32767)
        throw ModelError(fmt::format("isg: backlash {:.1f} um of axis {} exceeds getriebe[0].lose (SGN16, 0.1 um)", backlashUm, axisName));
    return isgAxisHead(axisNumber, axisName) + fmt::format("lr_param.anwahl_losekomp            1\ngetriebe[0].lose                    {}\n", tenth);
}

std::string isgLaserLsec(const LaserPositioningResult& r, int axisNumber, const std::string& axisName) {
    const LaserAxisCompensation c = laserAxisCompensation(r);
    const auto tenthUm = [](double um) { return std::lround(um * 10.0); };
    std::string s;
    s += fmt::format("# cnccomp laser: leadscrew error compensation (bilateral LSEC) of axis {} from ISO 230-2 laser runs\n", r.axis);
    s += "# values: actual - setpoint in 0.1 um per direction (Beckhoff TF5200 LSEC example); positions in 0.1 um\n";
    s += "# bilateral: the two tables hold the reversal; no backlash compensation besides (P-AXIS-00021 = 0)\n";
    s += "# axis parameter list of this axis: lr_param.ssfk 1 (P-AXIS-00175), lr_param.anwahl_losekomp 0 (P-AXIS-00021)\n";
    s += "# " + servoMismatchNote("the axes' position controller gain (kv) in the axis parameter list [G]") + "\n";
    s += "# measured with the axis' LSEC and backlash compensation off\n";
    s += isgAxisHead(axisNumber, axisName);
    s += "kw.ssfk.interval                    0\n";
    s += fmt::format("kw.ssfk.kw_startpos                 {}\n", tenthUm(c.positions.front() * 1000));
    s += fmt::format("kw.ssfk.kw_nr_max                   {}\n", c.positions.size());
    s += "kw.ssfk.unit                        1\n";
    s += "kw.ssfk.bilateral                   1\n";
    s += "kw.ssfk.modulo                      0\n";
    for (size_t i = 0; i < c.positions.size(); ++i)
        s += fmt::format("kw.ssfk.table[{}].setpoint {}\n", i, tenthUm(c.positions[i] * 1000));
    for (size_t i = 0; i < c.positions.size(); ++i) s += fmt::format("kw.ssfk.table[{}].pos {}\n", i, tenthUm(c.forwardUm[i]));
    for (size_t i = 0; i < c.positions.size(); ++i) s += fmt::format("kw.ssfk.table[{}].neg {}\n", i, tenthUm(c.reverseUm[i]));
    return s;
}

}  // namespace cnccomp::controllers::isg
