#include "cnccomp/deviations.hpp"

#include <fmt/format.h>

#include "cnccomp/error.hpp"

namespace cnccomp {

DeviationSet::DeviationSet(const MachineModel& machine)
    : values(Eigen::VectorXd::Zero(machine.parameterCount())),
      present(machine.deviations.size(), 0),
      reversal(static_cast<size_t>(machine.axisCount()), 0.0),
      reversalPresent(static_cast<size_t>(machine.axisCount()), 0),
      machine_(&machine) {}

int DeviationSet::require(std::string_view nameOrAlias) const {
    const int i = machine_->deviationIndex(nameOrAlias);
    if (i < 0)
        throw ModelError(fmt::format("machine '{}' has no deviation named '{}'", machine_->name, nameOrAlias));
    return i;
}

namespace {
const DeviationDef& location(const MachineModel& m, int i) {
    const DeviationDef& d = m.deviations[static_cast<size_t>(i)];
    if (d.kind != DeviationKind::Location)
        throw ModelError(fmt::format("deviation '{}' is a component error; use its coefficients", d.name));
    return d;
}
}  // namespace

double DeviationSet::isoValue(int index) const {
    const DeviationDef& d = location(*machine_, index);
    double v = 0.0;
    for (const DeviationTerm& t : d.isoTerms)
        v += t.coefficient * values[machine_->deviations[static_cast<size_t>(t.deviation)].offset];
    return v;
}

double DeviationSet::aliasValue(int index, int k) const {
    const DeviationDef& d = machine_->deviations.at(static_cast<size_t>(index));
    return d.aliasSign * values[d.offset + k];
}

void DeviationSet::setIsoValue(int index, double value) {
    location(*machine_, index);
    const double delta = value - isoValue(index);
    // Column `index` of the inverse relation: how every link value moves when this ISO value alone changes.
    for (const DeviationDef& o : machine_->deviations)
        for (const DeviationTerm& t : o.linkTerms)
            if (t.deviation == index) values[o.offset] += t.coefficient * delta;
    present[static_cast<size_t>(index)] = 1;
}

double DeviationSet::get(std::string_view nameOrAlias) const {
    const int i = require(nameOrAlias);
    const DeviationDef& d = location(*machine_, i);
    return d.name == nameOrAlias ? isoValue(i) : aliasValue(i);
}

void DeviationSet::set(std::string_view nameOrAlias, double value) {
    const int i = require(nameOrAlias);
    const DeviationDef& d = location(*machine_, i);
    if (d.name == nameOrAlias) return setIsoValue(i, value);
    values[d.offset] = d.aliasSign * value;
    present[static_cast<size_t>(i)] = 1;
}

double DeviationSet::linkValue(std::string_view nameOrAlias) const {
    return values[location(*machine_, require(nameOrAlias)).offset];
}

void DeviationSet::setLinkValue(std::string_view nameOrAlias, double value) {
    const int i = require(nameOrAlias);
    values[location(*machine_, i).offset] = value;
    present[static_cast<size_t>(i)] = 1;
}

void DeviationSet::setReversal(std::string_view axis, double valueMm) {
    const int a = machine_->requireAxis(axis);
    if (machine_->axisLink(a).kind != AxisKind::Linear)
        throw ModelError(fmt::format("axis {} of machine '{}' is not linear: a reversal value (ISO 230-2) is of a linear axis",
                                     axis, machine_->name));
    reversal[static_cast<size_t>(a)] = valueMm;
    reversalPresent[static_cast<size_t>(a)] = 1;
}

bool DeviationSet::hasReversal() const {
    for (char p : reversalPresent)
        if (p) return true;
    return false;
}

void DeviationSet::requireMachine(const MachineModel& m) const {
    if (machine_ != &m && machine_->name != m.name)
        throw ModelError(fmt::format("deviation set is for machine '{}', not '{}'", machine_->name, m.name));
}

}  // namespace cnccomp
