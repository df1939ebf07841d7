#include "controllers/common/set_backlash.hpp"

#include "cnccomp/geometry.hpp"

namespace cnccomp::controllers::common {

std::vector<AxisBacklash> backlashOfSet(const EmitRequest& r) {
    std::vector<AxisBacklash> out;
    const MachineModel& m = r.machine;
    const DeviationSet& d = r.deviations;
    for (int a = 0; a < m.axisCount() && a < static_cast<int>(d.reversalPresent.size()); ++a) {
        if (!d.reversalPresent[static_cast<size_t>(a)] || m.axisLink(a).kind != AxisKind::Linear) continue;
        AxisBacklash b;
        b.axis = a;
        b.name = m.axisNames[static_cast<size_t>(a)];
        b.reversalUm = d.reversal[static_cast<size_t>(a)] / kUm;
        b.backlashUm = backlashFromMeanReversalUm(b.reversalUm);
        out.push_back(b);
    }
    return out;
}

AxisVector withBacklashOffsets(const AxisVector& drive, const std::vector<double>& beta, const AxisVector& motion) {
    AxisVector out = drive;
    for (long a = 0; a < out.size() && a < static_cast<long>(beta.size()); ++a)
        if (beta[static_cast<size_t>(a)] != 0.0)
            out[a] += backlashDriveOffset(beta[static_cast<size_t>(a)], a < motion.size() ? motion[a] : 0.0);
    return out;
}

}  // namespace cnccomp::controllers::common
