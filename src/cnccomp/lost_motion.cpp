#include "cnccomp/lost_motion.hpp"

#include <cmath>

namespace cnccomp {

std::vector<AxisVector> motionDirections(const std::vector<AxisVector>& q, double rest) {
    std::vector<AxisVector> s;
    if (q.empty()) return s;
    const long n = q.front().size();
    s.assign(q.size(), AxisVector::Zero(n));
    for (long a = 0; a < n; ++a) {
        double current = 0;
        for (size_t i = 1; i < q.size(); ++i) {
            const double step = q[i][a] - q[i - 1][a];
            if (std::abs(step) > rest) current = step > 0 ? 1.0 : -1.0;
            s[i][a] = current;
        }
        // The samples before the first motion: the direction of that motion.
        size_t first = 0;
        while (first < q.size() && s[first][a] == 0) ++first;
        for (size_t i = 0; i < first && first < q.size(); ++i) s[i][a] = s[first][a];
    }
    return s;
}

AxisVector withLostMotion(const DeviationSet& d, const AxisVector& q, const AxisVector& s) {
    AxisVector a = q;
    for (long k = 0; k < q.size() && k < static_cast<long>(d.reversalPresent.size()); ++k)
        if (d.reversalPresent[static_cast<size_t>(k)]) a[k] += 0.5 * d.reversal[static_cast<size_t>(k)] * s[k];
    return a;
}

std::vector<AxisVector> withLostMotion(const DeviationSet& d, const std::vector<AxisVector>& q) {
    const std::vector<AxisVector> s = motionDirections(q);
    std::vector<AxisVector> out;
    out.reserve(q.size());
    for (size_t i = 0; i < q.size(); ++i) out.push_back(withLostMotion(d, q[i], s[i]));
    return out;
}

}  // namespace cnccomp
