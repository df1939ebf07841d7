#include "cnccomp/identification/staged_fit.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include <fmt/format.h>

#include "cnccomp/identification/parameters.hpp"

namespace cnccomp::identification {

namespace {

/// A run of another Observations list, seen without owning it (stage 1 fits a subset of the runs).
class ObservationView final : public ObservationModel {
public:
    explicit ObservationView(const ObservationModel& o) : o_(&o) {}
    std::string runName() const override { return o_->runName(); }
    std::string kind() const override { return o_->kind(); }
    int size() const override { return o_->size(); }
    const Eigen::VectorXd& measured() const override { return o_->measured(); }
    double weight() const override { return o_->weight(); }
    int nuisanceCount() const override { return o_->nuisanceCount(); }
    std::vector<std::string> nuisanceNames() const override { return o_->nuisanceNames(); }
    void nuisanceInitial(double* out) const override { o_->nuisanceInitial(out); }
    double nuisanceScale(int i) const override { return o_->nuisanceScale(i); }
    void predict(const Kinematics& k, const double* nuisance, double* out) const override { o_->predict(k, nuisance, out); }
    bool jacobian(const DifferentiableMachine& m, const double* nuisance, const std::vector<int>& flat,
                  Eigen::Ref<Eigen::MatrixXd> J) const override {
        return o_->jacobian(m, nuisance, flat, J);
    }
    std::vector<double> sweepAnglesDeg() const override { return o_->sweepAnglesDeg(); }
    std::vector<std::string> turningAxes() const override { return o_->turningAxes(); }
    bool movesOnlyLinearAxes() const override { return o_->movesOnlyLinearAxes(); }

private:
    const ObservationModel* o_;
};

/// Copies deviation d from `from` into `to` as the engine holds a deviation it does not estimate: a location error by
/// its ISO value (iso_names.hpp), a component error by its coefficients.
void copyDeviation(const MachineModel& m, int d, const DeviationSet& from, DeviationSet& to) {
    const DeviationDef& def = m.deviations[static_cast<size_t>(d)];
    if (def.kind == DeviationKind::Location) {
        to.setIsoValue(d, from.isoValue(d));
        return;
    }
    for (int c = 0; c < def.size(); ++c) to.values[def.offset + c] = from.values[def.offset + c];
}

std::string joined(const std::vector<std::string>& v) {
    std::string s;
    for (const std::string& x : v) s += (s.empty() ? "" : " ") + x;
    return s;
}

}  // namespace

IdentificationResult identifyStaged(const MachineModel& machine, const Observations& observations,
                                    const IdentifyOptions& options) {
    std::vector<int> devs = options.deviations;
    if (devs.empty())
        for (int i = 0; i < static_cast<int>(machine.deviations.size()); ++i) devs.push_back(i);
    std::sort(devs.begin(), devs.end());
    Observations linear;
    std::vector<std::string> linearRuns;
    for (const auto& o : observations)
        if (o->movesOnlyLinearAxes()) {
            linear.push_back(std::make_unique<ObservationView>(*o));
            linearRuns.push_back(o->runName());
        }
    if (!options.staged || linear.empty() || linear.size() == observations.size()) return identify(machine, observations, options);

    // Stage 1: the linear-axis runs alone, every requested deviation; keep those fully identified there.
    IdentifyOptions o1 = options;
    o1.deviations = devs;
    const IdentificationResult r1 = identify(machine, linear, o1);
    std::vector<int> first, second;
    for (int d : devs) (r1.deviations.present[static_cast<size_t>(d)] ? first : second).push_back(d);
    if (first.empty() || second.empty()) return identify(machine, observations, options);

    // Stage 2: every run, the stage-1 deviations held at their stage-1 values.
    IdentifyOptions o2 = options;
    o2.deviations = second;
    DeviationSet held = options.start ? *options.start : DeviationSet(machine);
    for (int d : first) copyDeviation(machine, d, r1.deviations, held);
    const UnknownLayout L1(machine, devs, linear);
    const Eigen::VectorXd x1 = L1.pack(r1.deviations, r1.nuisance);
    std::vector<int> s1;  // stage-1 unknowns (indices into L1) of the stage-1 deviations
    for (int i = 0; i < L1.size(); ++i)
        if (!L1[i].nuisance && std::binary_search(first.begin(), first.end(), L1[i].deviation)) s1.push_back(i);
    o2.start = held;
    IdentificationResult r2 = identify(machine, observations, o2);

    // G = ∂θ₂/∂θ₁ by one more stage-2 fit per stage-1 unknown, moved by its standard deviation from r2's solution.
    const UnknownLayout L2(machine, second, observations);
    const Eigen::VectorXd x2 = L2.pack(r2.deviations, r2.nuisance);
    const int n1 = static_cast<int>(s1.size()), n2 = L2.size();
    Eigen::MatrixXd G = Eigen::MatrixXd::Zero(n2, n1);
    Eigen::MatrixXd C1(n1, n1);
    for (int a = 0; a < n1; ++a)
        for (int b = 0; b < n1; ++b) C1(a, b) = r1.report.covariance(s1[a], s1[b]);
    const bool propagate = C1.allFinite();  // unidentified stage-2 unknowns keep their NaN rows
    for (int k = 0; k < n1 && propagate; ++k) {
        const double sd = std::sqrt(std::max(0.0, C1(k, k)));
        if (!(sd > 0)) continue;
        Eigen::VectorXd xk = x1;
        xk[s1[k]] += sd / L1[s1[k]].scale;
        DeviationSet shifted = r1.deviations;
        Eigen::VectorXd nu;
        L1.unpack(xk, shifted, nu);
        DeviationSet moved = r2.deviations;  // the stage-2 deviations start from r2's solution
        for (int d : first) copyDeviation(machine, d, shifted, moved);
        IdentifyOptions ok = o2;
        ok.start = moved;
        ok.monteCarlo = 0;
        const IdentificationResult rk = identify(machine, observations, ok);
        const Eigen::VectorXd xk2 = L2.pack(rk.deviations, rk.nuisance);
        for (int j = 0; j < n2; ++j) G(j, k) = (xk2[j] - x2[j]) * L2[j].scale / sd;
    }

    // The merged report, in the order of one fit of every requested deviation.
    const UnknownLayout L(machine, devs, observations);
    IdentificationReport rep = r2.report;
    std::map<std::string, int> at1, at2;
    for (int a = 0; a < n1; ++a) at1[L1[s1[a]].name] = a;
    for (int j = 0; j < n2; ++j) at2[L2[j].name] = j;
    const Eigen::MatrixXd C2 = propagate ? Eigen::MatrixXd(r2.report.covariance + G * C1 * G.transpose())
                                         : r2.report.covariance;
    const Eigen::MatrixXd C21 = G * C1;
    rep.parameters.clear();
    rep.covariance = Eigen::MatrixXd::Constant(L.size(), L.size(), kNaN);
    std::vector<std::pair<int, int>> where;  // (stage, index in it) for each unknown of L
    for (int i = 0; i < L.size(); ++i) {
        const auto f1 = at1.find(L[i].name);
        if (!L[i].nuisance && f1 != at1.end()) {
            rep.parameters.push_back(r1.report.parameters[static_cast<size_t>(s1[f1->second])]);
            where.emplace_back(1, f1->second);
        } else {
            const int j = at2.at(L[i].name);
            ParameterEstimate e = r2.report.parameters[static_cast<size_t>(j)];
            const double before = e.stddev, after = std::sqrt(std::max(0.0, C2(j, j)));
            if (propagate && e.identified && before > 0 && std::isfinite(after)) {
                const double f = after / before;
                e.stddev = after;
                e.lower95 = e.value - f * (e.value - e.lower95);
                e.upper95 = e.value + f * (e.upper95 - e.value);
            }
            rep.parameters.push_back(e);
            where.emplace_back(2, j);
        }
    }
    for (int a = 0; a < L.size(); ++a)
        for (int b = 0; b < L.size(); ++b) {
            const auto [sa, ia] = where[static_cast<size_t>(a)];
            const auto [sb, ib] = where[static_cast<size_t>(b)];
            rep.covariance(a, b) = sa == 1 && sb == 1   ? C1(ia, ib)
                                   : sa == 2 && sb == 2 ? C2(ia, ib)
                                   : sa == 2            ? C21(ia, ib)
                                                        : C21(ib, ia);
        }
    rep.unknowns += n1;
    rep.rank += n1;
    std::vector<std::string> names1, names2;
    for (int d : first) names1.push_back(machine.deviations[static_cast<size_t>(d)].name);
    for (int d : second) names2.push_back(machine.deviations[static_cast<size_t>(d)].name);
    rep.stages = fmt::format("stage 1: {} from the runs that move only linear axes ({}), rank {} of {}, sigma {:.4f} um; "
                             "stage 2: {} from all {} runs with stage 1 held; the stage-2 intervals include stage 1's "
                             "uncertainty{}",
                             joined(names1), joined(linearRuns), r1.report.rank, r1.report.unknowns,
                             r1.report.sigma / kUm, joined(names2), observations.size(),
                             propagate ? "" : " (NOT propagated: the stage-1 covariance is not finite)");
    for (const std::string& w : r1.report.warnings)
        if (w.find("not identifiable") == std::string::npos)  // stage 1 leaves the rotary deviations to stage 2
            rep.warnings.push_back("stage 1 (" + joined(linearRuns) + "): " + w);

    IdentificationResult out{r2.deviations, r2.nuisance, std::move(rep)};
    for (int d : first) out.deviations.present[static_cast<size_t>(d)] = 1;
    return out;
}

}  // namespace cnccomp::identification
