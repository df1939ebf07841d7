#pragma once
// A deviation set: the machine's named deviation parameters as one flat vector (mm, rad) of link values — the error
// components of the kinematic chains. Names read and write them in their own conventions (iso_names.hpp): the ISO
// 230-1 name gives the value the standard defines (reference axis and sign), the paper alias the paper's value.
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
    /// Flat vector of link values in internal units (mm, rad); entries DeviationDef::offset .. offset+size().
    Eigen::VectorXd values;
    /// Which deviations were given (read from a file or identified); absent ones are zero.
    std::vector<char> present;

    /// Value of a location deviation under `nameOrAlias`, internal units: the ISO 230-1 value for its ISO name, the
    /// paper's value for its alias. Throws ModelError if unknown.
    double get(std::string_view nameOrAlias) const;
    /// Sets a location deviation so that its value under `nameOrAlias` is `value` (internal units) and marks it
    /// present. By ISO name the other deviations keep their ISO values; by alias the other link values stay.
    void set(std::string_view nameOrAlias, double value);
    /// Index of a deviation by name or alias; throws ModelError naming the machine when unknown.
    int require(std::string_view nameOrAlias) const;
    /// Throws ModelError when this set belongs to another machine than `m` (checked by name when the objects differ):
    /// every model that evaluates a set calls it, since the set's values are laid out for its own machine.
    void requireMachine(const MachineModel& m) const;

    /// ISO value of location deviation `index` (Σ isoTerms · link values).
    double isoValue(int index) const;
    /// Value under the alias of deviation `index`, coefficient k (aliasSign × link value).
    double aliasValue(int index, int k = 0) const;
    /// Sets the ISO value of location deviation `index`, keeping the other ISO values; marks it present.
    void setIsoValue(int index, double value);
    /// Link value of a location deviation (the error component the kinematics use), by name or alias.
    double linkValue(std::string_view nameOrAlias) const;
    /// Sets the link value of a location deviation by name or alias and marks it present.
    void setLinkValue(std::string_view nameOrAlias, double value);

    /// Reversal value of each controlled axis (index = AxisVector index), mm: the mean reversal value B̄ of ISO
    /// 230-2:2014 clause 2 (B_i = x̄_i↑ − x̄_i↓, the mean positional deviation reached approaching the target in the
    /// positive direction minus that reached approaching it in the negative direction; B̄ = the mean of B_i over the
    /// targets), with x the deviation of the tool relative to the workpiece along the direction in which a positive
    /// command of the axis moves the tool relative to the workpiece (laser_deviation.hpp). Lost motion (the slide lags
    /// its motor on a reversal) gives B̄ < 0. Linear axes only (setReversal refuses a rotary one). It depends on the
    /// approach direction, so the kinematics, the volumetric map and the direction-free tables leave it out; the
    /// controllers take it as backlash. CSV row name B<axis> (io/deviation_csv.hpp).
    std::vector<double> reversal;
    std::vector<char> reversalPresent;
    /// Sets the reversal value (mm) of axis `axis` (by name) and marks it present; ModelError for an unknown or a
    /// non-linear axis.
    void setReversal(std::string_view axis, double valueMm);
    /// True when some axis has a reversal value.
    bool hasReversal() const;

private:
    const MachineModel* machine_;
};

}  // namespace cnccomp
