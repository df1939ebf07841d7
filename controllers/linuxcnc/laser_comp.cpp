#include "controllers/linuxcnc/laser_comp.hpp"

#include <fmt/format.h>

#include "cnccomp/error.hpp"

namespace cnccomp::controllers::linuxcnc {

CompTable compTableFromLaser(const LaserPositioningResult& r) {
    if (r.targets.size() > static_cast<size_t>(kMaxCompLines))
        throw ModelError(fmt::format("axis {}: {} laser targets, but a LinuxCNC compensation table holds at most {} "
                                     "lines (motion.h EMCMOT_COMP_SIZE)", r.axis, r.targets.size(), kMaxCompLines));
    CompTable t;
    for (const LaserTargetResult& p : r.targets) {
        t.nominal.push_back(p.target);
        t.forward.push_back(-p.meanForward / 1000.0);
        t.reverse.push_back(-p.meanReverse / 1000.0);
    }
    return t;
}

double backlashFromLaser(const LaserPositioningResult& r) { return backlashFromReversal(r.meanReversal / 1000.0); }

std::string laserCompIniLines(const LaserPositioningResult& r, int joint, const std::string& fileName) {
    const double backlash = backlashFromLaser(r);
    std::string o = fmt::format("[JOINT_{}]\nCOMP_FILE = {}\nCOMP_FILE_TYPE = 1\n", joint, fileName);
    // A relative COMP_FILE is opened from the INI file's folder: usrmotintf.cc usrmotLoadComp fopen()s the name as
    // given, and scripts/linuxcnc.in changes to the INI's folder before starting LinuxCNC.
    o += fmt::format("# {} beside the INI file (a relative COMP_FILE is opened from the INI's folder).\n", fileName);
    o += fmt::format("# The table carries the reversal (forward and reverse columns): BACKLASH is not needed, and "
                     "LinuxCNC ignores it on a joint with a COMP_FILE (ini-config.adoc).\n"
                     "# Without the table, the mean reversal alone would be BACKLASH = {:.6f} (mm, = -B-bar; "
                     "no pitch-error correction then)",
                     backlash);
    if (backlash < 0) o += kNegativeBacklashNote;
    o += "\n";
    return o;
}

}  // namespace cnccomp::controllers::linuxcnc
