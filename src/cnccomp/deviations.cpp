#include "cnccomp/deviations.hpp"

#include <fmt/format.h>

#include "cnccomp/error.hpp"

namespace cnccomp {

DeviationSet::DeviationSet(const MachineModel& machine)
    : values(Eigen::VectorXd::Zero(machine.parameterCount())),
      present(machine.deviations.size(), 0),
      machine_(&machine) {}

int DeviationSet::require(std::string_view nameOrAlias) const {
    const int i = machine_->deviationIndex(nameOrAlias);
    if (i < 0)
        throw ModelError(fmt::format("machine '{}' has no deviation named '{}'", machine_->name, nameOrAlias));
    return i;
}

double DeviationSet::get(std::string_view nameOrAlias) const {
    const auto& d = machine_->deviations[require(nameOrAlias)];
    return values[d.offset];
}

void DeviationSet::set(std::string_view nameOrAlias, double value) {
    const int i = require(nameOrAlias);
    const auto& d = machine_->deviations[i];
    if (d.kind != DeviationKind::Location)
        throw ModelError(fmt::format("deviation '{}' is a component error; set its coefficients", d.name));
    values[d.offset] = value;
    present[i] = 1;
}

}  // namespace cnccomp
