#include "cnccomp/eccentricity.hpp"

#include "cnccomp/error.hpp"

namespace cnccomp {

std::vector<EccentricityRow> eccentricitiesFromTraces(const MachineModel& m, const std::vector<BallbarRun>& runs,
                                                      const std::vector<BallbarTrace>& traces) {
    if (runs.size() != traces.size()) throw ModelError("eccentricities: one trace per run is needed");
    std::vector<EccentricityRow> rows;
    for (size_t i = 0; i < runs.size(); ++i) {
        const BallbarRun& r = runs[i];
        rows.push_back({r.test, r.LB, r.RB, r.RC, r.ZC, traceEccentricity(m, r, traces[i]), "run '" + r.name + "'"});
    }
    return rows;
}

}  // namespace cnccomp
