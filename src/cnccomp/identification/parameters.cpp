#include "cnccomp/identification/parameters.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "cnccomp/error.hpp"

namespace cnccomp::identification {

double coefficientScale(const MachineModel& machine, const DeviationDef& d, int k) {
    const double unit = d.isAngle() ? kArcsec : kUm;
    if (d.kind != DeviationKind::Component || d.basis.type != ComponentBasis::Type::Polynomial) return unit;
    const Link& l = machine.chain(d.side).links[d.link];
    double range = std::max(std::abs(l.min), std::abs(l.max));
    if (!std::isfinite(range) || range <= 0) range = l.kind == AxisKind::Rotary ? kPi : 500.0;
    if (l.kind == AxisKind::Rotary) range = std::min(range, kPi);
    return unit / std::pow(range, k + 1);  // term q^(k+1) reaches one unit at q = range
}

UnknownLayout::UnknownLayout(const MachineModel& machine, const std::vector<int>& deviations,
                             const Observations& observations)
    : machine_(&machine), deviations_(deviations) {
    for (int di : deviations) {
        if (di < 0 || di >= static_cast<int>(machine.deviations.size()))
            throw ModelError(fmt::format("deviation index {} outside machine '{}'", di, machine.name));
        const DeviationDef& d = machine.deviations[di];
        for (int k = 0; k < d.size(); ++k) {
            UnknownInfo u;
            const bool comp = d.kind == DeviationKind::Component;
            u.name = comp ? fmt::format("{}[{}]", d.name, k) : d.name;
            u.alias = d.alias.empty() ? "" : comp ? fmt::format("{}[{}]", d.alias, k) : d.alias;
            u.angle = d.isAngle();
            u.scale = coefficientScale(machine, d, k);
            u.deviation = di;
            u.flat = d.offset + k;
            unknowns_.push_back(u);
            flat_.push_back(u.flat);
        }
    }
    // Link values moved through another name's reference (linkTerms naming an estimated location error).
    const int nd = static_cast<int>(unknowns_.size());
    deviationUnknowns_ = nd;
    for (const DeviationDef& o : machine.deviations)
        for (const DeviationTerm& t : o.linkTerms)
            if (std::find(deviations.begin(), deviations.end(), t.deviation) != deviations.end() &&
                std::find(flat_.begin(), flat_.end(), o.offset) == flat_.end())
                flat_.push_back(o.offset);
    transform_ = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(flat_.size()), nd);
    for (int u = 0; u < nd; ++u) {
        const DeviationDef& d = machine.deviations[static_cast<size_t>(unknowns_[u].deviation)];
        if (d.kind == DeviationKind::Component) {
            transform_(u, u) = 1.0;
            continue;
        }
        for (size_t f = 0; f < flat_.size(); ++f) {
            const auto owner = std::find_if(machine.deviations.begin(), machine.deviations.end(), [&](const DeviationDef& o) {
                return o.kind == DeviationKind::Location && o.offset == flat_[f];
            });
            if (owner == machine.deviations.end()) continue;
            for (const DeviationTerm& t : owner->linkTerms)
                if (t.deviation == unknowns_[u].deviation) transform_(static_cast<Eigen::Index>(f), u) = t.coefficient;
        }
    }
    for (size_t r = 0; r < observations.size(); ++r) {
        nuisanceStart_.push_back(size());
        const ObservationModel& o = *observations[r];
        const std::vector<std::string> names = o.nuisanceNames();
        if (static_cast<int>(names.size()) != o.nuisanceCount())
            throw ModelError(fmt::format("run '{}': {} nuisance names for {} nuisance parameters", o.runName(),
                                         names.size(), o.nuisanceCount()));
        for (int i = 0; i < o.nuisanceCount(); ++i) {
            UnknownInfo u;
            u.name = names[i];
            u.nuisance = true;
            u.scale = o.nuisanceScale(i);
            u.angle = std::abs(u.scale - kArcsec) < 1e-3 * kArcsec;
            u.run = static_cast<int>(r);
            u.nuisanceIndex = i;
            unknowns_.push_back(u);
        }
    }
}

namespace {
/// The unknown's value in `set`: the ISO value of a location error, the coefficient of a component error.
double unknownValue(const MachineModel& m, const DeviationSet& set, const UnknownInfo& u) {
    return m.deviations[static_cast<size_t>(u.deviation)].kind == DeviationKind::Location ? set.isoValue(u.deviation)
                                                                                            : set.values[u.flat];
}
}  // namespace

void UnknownLayout::unpack(const Eigen::VectorXd& x, DeviationSet& set, Eigen::VectorXd& nuisance) const {
    const int nd = deviationUnknowns();
    Eigen::VectorXd delta(nd);
    for (int i = 0; i < nd; ++i) delta[i] = x[i] * unknowns_[i].scale - unknownValue(*machine_, set, unknowns_[i]);
    const Eigen::VectorXd move = transform_ * delta;
    for (size_t f = 0; f < flat_.size(); ++f)
        if (move[static_cast<Eigen::Index>(f)] != 0.0) set.values[flat_[f]] += move[static_cast<Eigen::Index>(f)];
    for (int i = nd; i < size(); ++i) nuisance[i - nd] = x[i] * unknowns_[i].scale;
}

Eigen::VectorXd UnknownLayout::pack(const DeviationSet& set, const Eigen::VectorXd& nuisance) const {
    Eigen::VectorXd x(size());
    for (int i = 0; i < size(); ++i) {
        const UnknownInfo& u = unknowns_[i];
        x[i] = (u.nuisance ? nuisance[i - deviationUnknowns()] : unknownValue(*machine_, set, u)) / u.scale;
    }
    return x;
}

std::vector<int> parseDeviationList(const MachineModel& machine, std::string_view list) {
    std::vector<int> out;
    std::string token;
    const auto flush = [&] {
        if (token.empty()) return;
        if (token == "all") {
            for (int i = 0; i < static_cast<int>(machine.deviations.size()); ++i) out.push_back(i);
        } else {
            const int i = machine.deviationIndex(token);
            if (i < 0) {
                std::string names;
                for (const DeviationDef& d : machine.deviations)
                    names += fmt::format("{}{}{}", names.empty() ? "" : ", ", d.name, d.alias.empty() ? "" : "/" + d.alias);
                throw ModelError(fmt::format("unknown deviation '{}' for machine '{}' (known: {})", token, machine.name,
                                             names));
            }
            out.push_back(i);
        }
        token.clear();
    };
    for (char c : list) {
        if (c == ',' || c == ';' || c == ' ' || c == '\t' || c == '\n') flush();
        else token += c;
    }
    flush();
    if (out.empty()) throw ModelError("the deviation list is empty");
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
}

}  // namespace cnccomp::identification
