#include "cnccomp/identification/parameters.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "cnccomp/error.hpp"

namespace cnccomp {

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

void UnknownLayout::unpack(const Eigen::VectorXd& x, DeviationSet& set, Eigen::VectorXd& nuisance) const {
    for (int i = 0; i < size(); ++i) {
        const UnknownInfo& u = unknowns_[i];
        if (u.nuisance) nuisance[i - deviationUnknowns()] = x[i] * u.scale;
        else set.values[u.flat] = x[i] * u.scale;
    }
}

Eigen::VectorXd UnknownLayout::pack(const DeviationSet& set, const Eigen::VectorXd& nuisance) const {
    Eigen::VectorXd x(size());
    for (int i = 0; i < size(); ++i) {
        const UnknownInfo& u = unknowns_[i];
        x[i] = (u.nuisance ? nuisance[i - deviationUnknowns()] : set.values[u.flat]) / u.scale;
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

}  // namespace cnccomp
