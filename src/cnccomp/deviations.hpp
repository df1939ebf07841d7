#pragma once
// A deviation set: the machine's named deviation parameters as one flat vector (mm, rad).
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "cnccomp/machine.hpp"

namespace cnccomp {

class DeviationSet {
public:
    /// All parameters zero and absent.
    explicit DeviationSet(const MachineModel& machine);

    const MachineModel& machine() const { return *machine_; }
    /// Flat vector in internal units (mm, rad); entries of DeviationDef::offset .. offset+size().
    Eigen::VectorXd values;
    /// Which deviations were given (read from a file or identified); absent ones are zero.
    std::vector<char> present;

    /// Value of a location deviation by ISO name or alias, internal units. Throws ModelError if unknown.
    double get(std::string_view nameOrAlias) const;
    /// Set a location deviation by ISO name or alias, internal units; marks it present.
    void set(std::string_view nameOrAlias, double value);
    /// Index of a deviation by name or alias; throws ModelError naming the machine when unknown.
    int require(std::string_view nameOrAlias) const;

private:
    const MachineModel* machine_;
};

}  // namespace cnccomp
