#include "cnccomp/laser_positioning.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "cnccomp/error.hpp"

namespace cnccomp {

namespace {

void checkLaserRuns(const LaserPositioningRuns& in) {
    const auto fail = [&](const std::string& what) {
        throw InputError(in.source, 0, fmt::format("laser positioning of axis {}: {}", in.axis, what));
    };
    if (in.forward.empty() != in.reverse.empty())
        fail(fmt::format("runs in one direction only ({} forward, {} reverse); ISO 230-2 needs bidirectional runs, "
                         "each target approached in the positive and the negative direction",
                         in.forward.size(), in.reverse.size()));
    if (in.forward.empty()) fail("no runs; expected bidirectional runs (targets × runs × direction)");
    if (in.forward.size() != in.reverse.size())
        fail(fmt::format("{} forward runs but {} reverse runs; expected as many in each direction",
                         in.forward.size(), in.reverse.size()));
    if (in.minimumRuns < 2) fail(fmt::format("minimumRuns is {}; at least 2 runs are needed for a repeatability",
                                             in.minimumRuns));
    if (static_cast<int>(in.forward.size()) < in.minimumRuns)
        fail(fmt::format("{} runs in each direction; ISO 230-2 4.3.2 asks for at least {}", in.forward.size(),
                         in.minimumRuns));
    if (in.targets.size() < 5)
        fail(fmt::format("{} target positions; ISO 230-2 4.3.2 asks for at least five", in.targets.size()));
    for (size_t i = 0; i < in.targets.size(); ++i) {
        if (!std::isfinite(in.targets[i])) fail(fmt::format("target {} is not a finite number", i + 1));
        if (i > 0 && !(in.targets[i] > in.targets[i - 1]))
            fail(fmt::format("target {} ({} mm) is not above target {} ({} mm); expected strictly increasing targets",
                             i + 1, in.targets[i], i, in.targets[i - 1]));
    }
    for (int dir = 0; dir < 2; ++dir) {
        const auto& runs = dir == 0 ? in.forward : in.reverse;
        for (size_t j = 0; j < runs.size(); ++j) {
            if (runs[j].size() != in.targets.size())
                fail(fmt::format("{} run {} has {} values for {} targets; expected one per target",
                                 dir == 0 ? "forward" : "reverse", j + 1, runs[j].size(), in.targets.size()));
            for (size_t i = 0; i < runs[j].size(); ++i)
                if (!std::isfinite(runs[j][i]))
                    fail(fmt::format("{} run {} at target {} ({} mm) is not a finite number",
                                     dir == 0 ? "forward" : "reverse", j + 1, i + 1, in.targets[i]));
        }
    }
}

}  // namespace

LaserPositioningResult evaluateLaserPositioning(const LaserPositioningRuns& in) {
    checkLaserRuns(in);
    LaserPositioningResult out;
    out.axis = in.axis;
    out.environmentCompensated = in.environmentCompensated;
    const size_t m = in.targets.size(), n = in.forward.size();
    out.runs = static_cast<int>(n);
    const auto meanAndS = [&](const std::vector<std::vector<double>>& runs, size_t i, double& mean, double& s) {
        double sum = 0;
        for (size_t j = 0; j < n; ++j) sum += runs[j][i];
        mean = sum / static_cast<double>(n);
        double ss = 0;
        for (size_t j = 0; j < n; ++j) ss += (runs[j][i] - mean) * (runs[j][i] - mean);
        s = std::sqrt(ss / static_cast<double>(n - 1));
    };
    double hiF = -HUGE_VAL, loF = HUGE_VAL, hiR = -HUGE_VAL, loR = HUGE_VAL, hiM = -HUGE_VAL, loM = HUGE_VAL;
    double aHiF = -HUGE_VAL, aLoF = HUGE_VAL, aHiR = -HUGE_VAL, aLoR = HUGE_VAL, sumB = 0;
    for (size_t i = 0; i < m; ++i) {
        LaserTargetResult t;
        t.target = in.targets[i];
        meanAndS(in.forward, i, t.meanForward, t.sForward);
        meanAndS(in.reverse, i, t.meanReverse, t.sReverse);
        t.mean = (t.meanForward + t.meanReverse) / 2;
        t.reversal = t.meanForward - t.meanReverse;
        t.repeatabilityForward = 4 * t.sForward;
        t.repeatabilityReverse = 4 * t.sReverse;
        t.repeatability = std::max({2 * t.sForward + 2 * t.sReverse + std::abs(t.reversal), t.repeatabilityForward,
                                    t.repeatabilityReverse});
        hiF = std::max(hiF, t.meanForward);
        loF = std::min(loF, t.meanForward);
        hiR = std::max(hiR, t.meanReverse);
        loR = std::min(loR, t.meanReverse);
        hiM = std::max(hiM, t.mean);
        loM = std::min(loM, t.mean);
        aHiF = std::max(aHiF, t.meanForward + 2 * t.sForward);
        aLoF = std::min(aLoF, t.meanForward - 2 * t.sForward);
        aHiR = std::max(aHiR, t.meanReverse + 2 * t.sReverse);
        aLoR = std::min(aLoR, t.meanReverse - 2 * t.sReverse);
        out.B = std::max(out.B, std::abs(t.reversal));
        sumB += t.reversal;
        out.RForward = std::max(out.RForward, t.repeatabilityForward);
        out.RReverse = std::max(out.RReverse, t.repeatabilityReverse);
        out.R = std::max(out.R, t.repeatability);
        out.targets.push_back(t);
    }
    out.EForward = hiF - loF;
    out.EReverse = hiR - loR;
    out.E = std::max(hiF, hiR) - std::min(loF, loR);
    out.M = hiM - loM;
    out.AForward = aHiF - aLoF;
    out.AReverse = aHiR - aLoR;
    out.A = std::max(aHiF, aHiR) - std::min(aLoF, aLoR);
    out.meanReversal = sumB / static_cast<double>(m);
    const double travel = in.targets.back() - in.targets.front();
    if (travel > 1000 && static_cast<double>(m) < 5 * travel / 1000)
        out.warnings.push_back(fmt::format("{} targets over {:.0f} mm; ISO 230-2 4.3.2 asks for at least five per "
                                           "metre ({:.0f})", m, travel, std::ceil(5 * travel / 1000)));
    if (!in.environmentCompensated)
        out.warnings.push_back("environment compensation not applied to the laser readings (stated as not done, or not "
                                "stated)");
    return out;
}

double LaserPositioningResult::errorAt(double mm, bool forward) const {
    if (targets.empty() || !std::isfinite(mm)) return std::numeric_limits<double>::quiet_NaN();
    const auto value = [&](const LaserTargetResult& t) { return forward ? t.meanForward : t.meanReverse; };
    if (mm <= targets.front().target) return value(targets.front());
    if (mm >= targets.back().target) return value(targets.back());
    const auto it = std::upper_bound(targets.begin(), targets.end(), mm,
                                     [](double p, const LaserTargetResult& t) { return p < t.target; });
    const LaserTargetResult& b = *it;
    const LaserTargetResult& a = *(it - 1);
    const double w = (mm - a.target) / (b.target - a.target);
    return value(a) + w * (value(b) - value(a));
}

}  // namespace cnccomp
