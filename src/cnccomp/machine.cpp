#include "cnccomp/machine.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/iso_names.hpp"

namespace cnccomp {

int ComponentBasis::size() const {
    switch (type) {
        case Type::Polynomial: return order;
        case Type::Fourier: return 2 * order;
        case Type::Table: return static_cast<int>(nodes.size());
    }
    return 0;
}

double ComponentBasis::evaluate(double q, const double* coef, bool moduloAxis) const {
    switch (type) {
        case Type::Polynomial: {
            double s = 0.0, p = q;
            for (int k = 0; k < order; ++k, p *= q) s += coef[k] * p;
            return s;
        }
        case Type::Fourier: {
            double s = 0.0;
            for (int k = 1; k <= order; ++k) s += coef[2 * k - 2] * std::cos(k * q) + coef[2 * k - 1] * std::sin(k * q);
            return s;
        }
        case Type::Table: {
            const int n = static_cast<int>(nodes.size());
            if (n == 0) return 0.0;
            if (moduloAxis) {
                // Wrap into [nodes[0], nodes[0] + 2π); the last interval closes on the first node.
                const double period = 2.0 * kPi;
                double u = std::fmod(q - nodes[0], period);
                if (u < 0) u += period;
                u += nodes[0];
                auto it = std::upper_bound(nodes.begin(), nodes.end(), u);
                const int i = static_cast<int>(it - nodes.begin()) - 1;
                const double x0 = nodes[i], y0 = coef[i];
                const double x1 = (i + 1 < n) ? nodes[i + 1] : nodes[0] + period;
                const double y1 = (i + 1 < n) ? coef[i + 1] : coef[0];
                return y0 + (y1 - y0) * (u - x0) / (x1 - x0);
            }
            if (q <= nodes.front()) return coef[0];
            if (q >= nodes.back()) return coef[n - 1];
            auto it = std::upper_bound(nodes.begin(), nodes.end(), q);
            const int i = static_cast<int>(it - nodes.begin()) - 1;
            return coef[i] + (coef[i + 1] - coef[i]) * (q - nodes[i]) / (nodes[i + 1] - nodes[i]);
        }
    }
    return 0.0;
}

AxisVector MachineModel::toController(const AxisVector& q) const {
    AxisVector p = q;
    for (int i = 0; i < axisCount() && i < p.size(); ++i) p[i] -= axisLink(i).machineZero;
    return p;
}

AxisVector MachineModel::fromController(const AxisVector& p) const {
    AxisVector q = p;
    for (int i = 0; i < axisCount() && i < q.size(); ++i) q[i] += axisLink(i).machineZero;
    return q;
}

bool MachineModel::hasMachineZero() const {
    for (const Chain* c : {&workpiece, &tool})
        for (const Link& l : c->links)
            if (l.axisIndex >= 0 && l.machineZero != 0.0) return true;
    return false;
}

int MachineModel::axisIndex(std::string_view axis) const {
    for (int i = 0; i < axisCount(); ++i)
        if (axisNames[i] == axis) return i;
    return -1;
}

int MachineModel::requireAxis(std::string_view axis) const {
    const int i = axisIndex(axis);
    if (i < 0) throw ModelError(fmt::format("machine '{}' has no axis named '{}'", name, axis));
    return i;
}

const Link& MachineModel::axisLink(int index) const {
    for (const Chain* c : {&workpiece, &tool})
        for (const Link& l : c->links)
            if (l.axisIndex == index) return l;
    throw ModelError(fmt::format("machine '{}' has no axis number {}", name, index));
}

Side MachineModel::axisSide(int index) const {
    for (const Link& l : tool.links)
        if (l.axisIndex == index) return Side::Tool;
    axisLink(index);  // throws for an unknown index
    return Side::Workpiece;
}

Vec3 MachineModel::nominalDirection(int index) const {
    Mat3 r = Mat3::Identity();
    for (const Link& l : chain(axisSide(index)).links) {
        r = r * l.placement.linear();
        if (l.axisIndex == index) return (r * l.direction).normalized();
    }
    throw ModelError(fmt::format("machine '{}' has no axis number {}", name, index));
}

int MachineModel::deviationIndex(std::string_view nameOrAlias) const {
    for (int i = 0; i < static_cast<int>(deviations.size()); ++i)
        if (deviations[i].name == nameOrAlias) return i;
    for (int i = 0; i < static_cast<int>(deviations.size()); ++i)
        if (!deviations[i].alias.empty() && deviations[i].alias == nameOrAlias) return i;
    return -1;
}

int MachineModel::parameterCount() const {
    return deviations.empty() ? 0 : deviations.back().offset + deviations.back().size();
}

void MachineModel::finalize() {
    axisNames.clear();
    for (Chain* c : {&workpiece, &tool}) {
        for (Link& l : c->links) {
            l.axisIndex = -1;
            if (l.kind == AxisKind::Fixed) continue;
            if (axisIndex(l.name) >= 0)
                throw ModelError(fmt::format("machine '{}': axis '{}' appears twice", name, l.name));
            if (static_cast<int>(axisNames.size()) >= kMaxAxes)
                throw ModelError(fmt::format("machine '{}': more than {} axes", name, kMaxAxes));
            if (!(l.min <= l.max))
                throw ModelError(fmt::format("machine '{}': axis '{}' has min > max", name, l.name));
            l.axisIndex = static_cast<int>(axisNames.size());
            axisNames.push_back(l.name);
        }
    }
    if (!(std::abs(toolDirection.norm() - 1.0) < 1e-9))
        throw ModelError(fmt::format("machine '{}': tool direction must be a unit vector", name));
    int offset = 0;
    for (DeviationDef& d : deviations) {
        const Chain& c = chain(d.side);
        if (d.link < 0 || d.link >= static_cast<int>(c.links.size()))
            throw ModelError(fmt::format("machine '{}': deviation '{}' names a link that does not exist", name, d.name));
        if (d.component < 0 || d.component > 5)
            throw ModelError(fmt::format("machine '{}': deviation '{}' has component outside x,y,z,a,b,c", name, d.name));
        if (d.kind == DeviationKind::Component && c.links[d.link].kind == AxisKind::Fixed)
            throw ModelError(fmt::format("machine '{}': component error '{}' on fixed link '{}'", name, d.name,
                                         c.links[d.link].name));
        d.offset = offset;
        offset += d.size();
    }
    for (size_t i = 0; i < deviations.size(); ++i)
        for (size_t j = 0; j < i; ++j) {
            const auto& a = deviations[i];
            const auto& b = deviations[j];
            if (a.name == b.name || (!a.alias.empty() && (a.alias == b.alias || a.alias == b.name)) ||
                (!b.alias.empty() && b.alias == a.name))
                throw ModelError(fmt::format("machine '{}': deviation names '{}' and '{}' clash", name, a.name, b.name));
        }
    for (const DeviationDef& d : deviations)
        if (d.aliasSign != 1.0 && d.aliasSign != -1.0)
            throw ModelError(fmt::format("machine '{}': the alias sign of '{}' must be +1 or -1", name, d.name));
    deriveIsoMeaning(*this);
}

}  // namespace cnccomp
