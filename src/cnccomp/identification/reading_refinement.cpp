#include "cnccomp/identification/reading_refinement.hpp"

#include <Eigen/LU>
#include <fmt/format.h>

#include "cnccomp/error.hpp"

namespace cnccomp::identification {

DeviationSet refineReadings(const MachineModel& m, const std::vector<int>& devs,
                            const std::function<Eigen::VectorXd(const DeviationSet&)>& readings,
                            const Eigen::VectorXd& measured, int steps) {
    const Eigen::Index n = static_cast<Eigen::Index>(devs.size());
    if (measured.size() != n) throw ModelError("refinement: one reading per deviation");
    DeviationSet set(m);
    const auto put = [&](DeviationSet& s, const Eigen::VectorXd& x) {
        for (Eigen::Index i = 0; i < n; ++i) {
            s.values[m.deviations[static_cast<size_t>(devs[static_cast<size_t>(i)])].offset] = x[i];
            s.present[static_cast<size_t>(devs[static_cast<size_t>(i)])] = 1;
        }
    };
    Eigen::VectorXd x = measured;
    put(set, x);
    if (steps <= 0) return set;
    // G by central differences on the nominal machine: 1 µm for lengths, 1 arcsec for angles.
    Eigen::MatrixXd G(n, n);
    for (Eigen::Index j = 0; j < n; ++j) {
        const DeviationDef& d = m.deviations[static_cast<size_t>(devs[static_cast<size_t>(j)])];
        const double h = d.isAngle() ? kArcsec : kUm;
        DeviationSet plus(m), minus(m);
        plus.values[d.offset] = h;
        minus.values[d.offset] = -h;
        G.col(j) = (readings(plus) - readings(minus)) / (2 * h);
    }
    const Eigen::FullPivLU<Eigen::MatrixXd> lu(G);
    if (lu.rank() < n) throw ModelError("refinement: the formula readings cannot tell these errors apart");
    x = lu.solve(measured);
    for (int k = 1; k < steps; ++k) {
        DeviationSet s(m);
        put(s, x);
        x += lu.solve(measured - readings(s));
    }
    put(set, x);
    return set;
}

}  // namespace cnccomp::identification
