#include "cnccomp/identification/adequacy.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include <Eigen/QR>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include "cnccomp/identification/identifiability.hpp"
#include "cnccomp/units.hpp"

namespace cnccomp::identification {
namespace {

constexpr double kInfiniteDof = 1e7;
/// Quantisation noise of a 0.1 µm resolution (q/√12) [G]: below it a data-derived noise estimate is not believed.
const double kNoiseFloor = 0.1 * kUm / std::sqrt(12.0);
constexpr int kHarmonics = 6;

struct Noise {
    std::string source;
    double sigma = kNaN, dof = 0;
};

Noise estimateNoise(const Eigen::VectorXd& r, const std::vector<double>& angles, double stated) {
    const Eigen::Index n = r.size();
    if (static_cast<Eigen::Index>(angles.size()) == n) {
        std::map<long long, std::vector<double>> groups;
        for (Eigen::Index i = 0; i < n; ++i) groups[std::llround(angles[static_cast<size_t>(i)] * 1e6)].push_back(r[i]);
        double ss = 0, dof = 0, repeated = 0;
        for (const auto& [key, v] : groups) {
            if (v.size() < 2) continue;
            double mean = 0;
            for (double a : v) mean += a / static_cast<double>(v.size());
            for (double a : v) ss += (a - mean) * (a - mean);
            dof += static_cast<double>(v.size()) - 1;
            repeated += static_cast<double>(v.size());
        }
        if (dof > 0 && repeated >= 0.5 * static_cast<double>(n))
            return {"passes", std::max(std::sqrt(ss / dof), kNoiseFloor), dof};
    }
    if (std::isfinite(stated) && stated > 0) return {"stated", stated, kInfiniteDof};
    if (static_cast<Eigen::Index>(angles.size()) == n && n >= 8) {
        double ss = 0;
        for (Eigen::Index i = 0; i + 1 < n; ++i) ss += (r[i + 1] - r[i]) * (r[i + 1] - r[i]);
        return {"successive differences", std::max(std::sqrt(ss / (2.0 * static_cast<double>(n - 1))), kNoiseFloor),
                2.0 * static_cast<double>(n - 1) / 3.0};
    }
    return {};
}

/// Amplitudes of orders 1..6 of r over the angles, and the share of Σ (r − mean)² that orders 1..6 carry.
void harmonics(const Eigen::VectorXd& r, const std::vector<double>& anglesDeg, RunAdequacy& out) {
    const Eigen::Index n = r.size();
    if (static_cast<Eigen::Index>(anglesDeg.size()) != n || n < 2 * (2 * kHarmonics + 1)) return;
    Eigen::MatrixXd A(n, 2 * kHarmonics + 1);
    for (Eigen::Index i = 0; i < n; ++i) {
        const double t = anglesDeg[static_cast<size_t>(i)] * kDeg;
        A(i, 0) = 1;
        for (int k = 1; k <= kHarmonics; ++k) {
            A(i, 2 * k - 1) = std::cos(k * t);
            A(i, 2 * k) = std::sin(k * t);
        }
    }
    const double total = r.squaredNorm();
    if (!(total > 0)) return;
    const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> full(A);
    const Eigen::VectorXd c = full.solve(r);
    const double mean = r.mean();
    const double centred = total - static_cast<double>(n) * mean * mean;
    const double restFull = (r - A * c).squaredNorm();
    out.harmonicShare = centred > 0 ? std::clamp((centred - restFull) / centred, 0.0, 1.0) : 0.0;
    for (int k = 1; k <= kHarmonics; ++k) out.harmonics.push_back(std::hypot(c[2 * k - 1], c[2 * k]));
}

double paulsonZ(double F, double d1, double d2) {
    const double a = 2.0 / (9.0 * d1), b = d2 >= kInfiniteDof ? 0.0 : 2.0 / (9.0 * d2);
    const double f3 = std::cbrt(F);
    return ((1 - b) * f3 - (1 - a)) / std::sqrt(b * f3 * f3 + a);
}

/// Component errors of rotary axis `axis` the machine has (ISO names E?<axis>), and which of them the fit estimated.
std::vector<std::string> componentNames(const MachineModel& m, const std::string& axis) {
    std::vector<std::string> out;
    for (const DeviationDef& d : m.deviations)
        if (d.kind == DeviationKind::Component && d.name.size() == 3 && d.name.substr(2) == axis) out.push_back(d.name);
    return out;
}

}  // namespace

double fQuantile(double p, double d1, double d2) {
    const double z = normalQuantile(p);
    double lo = -30, hi = 30;  // log F
    for (int i = 0; i < 200; ++i) {
        const double mid = 0.5 * (lo + hi);
        (paulsonZ(std::exp(mid), d1, d2) < z ? lo : hi) = mid;
    }
    return std::exp(0.5 * (lo + hi));
}

void testAdequacy(const LsqProblem& p, const Eigen::VectorXd& x, const IdentifyOptions& o, IdentificationReport& rep) {
    Adequacy& a = rep.adequacy;
    a = Adequacy{};
    Eigen::VectorXd r;
    p.residuals(x, r);
    const int m = p.rows();
    if (m <= rep.rank || m == 0) return;
    const double share = static_cast<double>(m - rep.rank) / m;
    std::vector<Eigen::VectorXd> segments;
    std::vector<std::vector<double>> angles;
    for (size_t k = 0; k < p.observations().size(); ++k) {
        const ObservationModel& ob = *p.observations()[k];
        const Eigen::VectorXd seg = r.segment(p.rowStart(static_cast<int>(k)), ob.size()) / ob.weight();
        const std::vector<double> ang = ob.sweepAnglesDeg();
        const Noise noise = estimateNoise(seg, ang, o.statedNoise);
        if (!std::isfinite(noise.sigma)) continue;
        RunAdequacy ra;
        ra.run = ob.runName();
        ra.noiseSource = noise.source;
        ra.noise = noise.sigma;
        ra.noiseDof = noise.dof;
        ra.dof = share * ob.size();
        ra.statistic = seg.squaredNorm() / ra.dof / (noise.sigma * noise.sigma);
        ra.turningAxes = ob.turningAxes();
        harmonics(seg, ang, ra);
        a.runs.push_back(ra);
        segments.push_back(seg);
        angles.push_back(ang);
    }
    if (a.runs.empty()) return;
    a.tested = true;
    const double perRun = 1 - (1 - a.confidence) / static_cast<double>(a.runs.size());
    double chi2 = 0;
    for (RunAdequacy& ra : a.runs) {
        ra.threshold = fQuantile(perRun, ra.dof, ra.noiseDof);
        ra.fits = ra.statistic <= ra.threshold;
        chi2 += ra.statistic * ra.dof;
        a.dof += ra.dof;
        a.noiseDof = std::min(kInfiniteDof, a.noiseDof + ra.noiseDof);
    }
    a.statistic = chi2 / a.dof;
    a.threshold = fQuantile(a.confidence, a.dof, a.noiseDof);
    a.fits = a.statistic <= a.threshold &&
             std::all_of(a.runs.begin(), a.runs.end(), [](const RunAdequacy& ra) { return ra.fits; });
    if (a.fits) return;

    // What is missing: the rotary axes turning in the failed runs whose residual is a pattern of orders 1–6, ranked by
    // how far their runs exceed the noise; linear-only runs point at the linear axes' motion errors.
    const MachineModel& machine = p.layout().machine();
    std::set<int> estimated;
    for (int i = 0; i < p.layout().size(); ++i)
        if (!p.layout()[i].nuisance) estimated.insert(p.layout()[i].deviation);
    std::map<std::string, double> excess;
    std::vector<std::string> failed, linearRuns;
    for (const RunAdequacy& ra : a.runs) {
        if (ra.fits) continue;
        failed.push_back(fmt::format("{} (rms {:.2f} um against noise {:.2f} um, {})", ra.run,
                                     std::sqrt(ra.statistic * ra.dof / (ra.dof / share)) * ra.noise / kUm, ra.noise / kUm,
                                     ra.noiseSource));
        const bool pattern = !(ra.harmonicShare < 0.5);
        if (ra.turningAxes.empty()) {
            if (pattern) linearRuns.push_back(ra.run);
            continue;
        }
        if (pattern)
            for (const std::string& ax : ra.turningAxes) excess[ax] += (ra.statistic - 1) * ra.dof;
    }
    std::vector<std::pair<double, std::string>> ranked;
    for (const auto& [ax, e] : excess) ranked.emplace_back(-e, ax);
    std::sort(ranked.begin(), ranked.end());
    std::vector<std::string> addNames;
    for (const auto& [e, ax] : ranked) {
        std::vector<std::string> names = componentNames(machine, ax), missing;
        for (const std::string& nm : names)
            if (!estimated.count(machine.deviationIndex(nm))) missing.push_back(nm);
        if (!missing.empty()) {
            a.suspected.push_back(fmt::format("component errors (error motions) of {}: {}", ax, fmt::join(missing, " ")));
            addNames.insert(addNames.end(), missing.begin(), missing.end());
        } else {
            a.suspected.push_back(fmt::format(
                "error motions of {} that the model's {} cannot carry (finer tables, or a run-out that turns with the axis)", ax,
                names.empty() ? "deviations" : fmt::format("tables {}", fmt::join(names, " "))));
        }
    }
    if (!linearRuns.empty())
        a.suspected.push_back(fmt::format("motion errors of the linear axes (straightness, angular, scale) or of the servo, "
                                          "seen in {}",
                                          fmt::join(linearRuns, ", ")));
    if (!addNames.empty()) a.option = fmt::format("{} (or --params with {} added)", o.componentOption, fmt::join(addNames, ","));

    // Widen the intervals by the residual's correlation (AR(1) variance inflation).
    double num = 0, den = 0;
    for (size_t k = 0; k < segments.size(); ++k) {
        const Eigen::VectorXd& s = segments[k];
        std::vector<Eigen::Index> order(static_cast<size_t>(s.size()));
        for (Eigen::Index i = 0; i < s.size(); ++i) order[static_cast<size_t>(i)] = i;
        if (angles[k].size() == static_cast<size_t>(s.size()))
            std::stable_sort(order.begin(), order.end(), [&](Eigen::Index i, Eigen::Index j) {
                return angles[k][static_cast<size_t>(i)] < angles[k][static_cast<size_t>(j)];
            });
        for (size_t i = 0; i + 1 < order.size(); ++i) num += s[order[i]] * s[order[i + 1]];
        den += s.squaredNorm();
    }
    const double rho = den > 0 ? std::clamp(num / den, 0.0, 0.999) : 0.0;
    a.inflation = std::sqrt((1 + rho) / (1 - rho));
    a.inflationRule = fmt::format(
        "stddev and 95 % intervals (already scaled with sigma = noise * sqrt(F)) widened by sqrt((1 + rho)/(1 - rho)) = "
        "{:.2f}, rho = {:.3f} the residual's lag-1 autocorrelation (AR(1) effective sample size)",
        a.inflation, rho);
    for (ParameterEstimate& e : rep.parameters) {
        if (!e.identified || !std::isfinite(e.stddev)) continue;
        const double half = (e.upper95 - e.lower95) / 2;
        e.stddev *= a.inflation;
        e.lower95 = e.value - half * a.inflation;
        e.upper95 = e.value + half * a.inflation;
    }
    rep.covariance *= a.inflation * a.inflation;
    for (Combination& c : rep.identifiable) c.stddev *= a.inflation;

    a.message = fmt::format(
        "the model does not fit the data: residual F = {:.1f} against {:.2f} allowed by the noise ({:.1f} % level; runs "
        "{}). Values absorb what the model lacks; intervals widened {:.1f}x. Likely missing: {}.{}",
        a.statistic, a.threshold, 100 * a.confidence, fmt::join(failed, "; "), a.inflation,
        a.suspected.empty() ? std::string("errors no run pattern points at") : fmt::format("{}", fmt::join(a.suspected, "; ")),
        a.option.empty() ? "" : " Add them with " + a.option + ".");
    rep.warnings.insert(rep.warnings.begin(), a.message);
}

}  // namespace cnccomp::identification
