#pragma once
// The unknowns of a least-squares identification: a chosen subset of the machine's deviation set (every
// coefficient of a component error is one unknown) followed by the runs' nuisance parameters. A location error is
// estimated as its ISO value (iso_names.hpp: the value under its ISO name, reference axis and sign included), so
// values, intervals, covariance and confounded combinations all read in ISO names; deviations that are not estimated
// keep their ISO values. The solver
// works in scaled units — µm for lengths, arcsec for angles, and for a polynomial coefficient of degree p the
// size that moves the error by 1 µm / 1 arcsec at the axis' typical range — so the problem is well conditioned.
#include <string>
#include <string_view>
#include <vector>

#include "cnccomp/identification/observation.hpp"

namespace cnccomp::identification {

struct UnknownInfo {
    std::string name;        ///< "EX0C", "EXC[2]" (component coefficient), "B-X.xT" (nuisance)
    std::string alias;       ///< "dxCZ", "" …
    bool nuisance = false;
    bool angle = false;      ///< unit arcsec (else µm)
    double scale = kUm;      ///< internal units per solver unit
    int deviation = -1;      ///< index into machine.deviations (-1 for nuisance)
    int flat = -1;           ///< the deviation's own entry of the deviation vector (-1 for nuisance)
    int run = -1;            ///< observation index (nuisance only)
    int nuisanceIndex = -1;  ///< index among the run's nuisance parameters
    /// Display unit: "um" or "arcsec".
    const char* unit() const { return angle ? "arcsec" : "um"; }
    /// Internal units per display unit (kUm or kArcsec).
    double displayScale() const { return angle ? kArcsec : kUm; }
    std::string label() const { return alias.empty() ? name : name + " (" + alias + ")"; }
};

class UnknownLayout {
public:
    /// `deviations`: indices into machine.deviations to estimate (all coefficients of each).
    UnknownLayout(const MachineModel& machine, const std::vector<int>& deviations, const Observations& observations);

    const MachineModel& machine() const { return *machine_; }
    int size() const { return static_cast<int>(unknowns_.size()); }
    int deviationUnknowns() const { return deviationUnknowns_; }
    const std::vector<UnknownInfo>& unknowns() const { return unknowns_; }
    const UnknownInfo& operator[](int i) const { return unknowns_[i]; }
    /// Entries of the deviation vector (link values) the deviation unknowns move: their own entries first, then
    /// the link values that change with an ISO value through the reference of another name (e.g. aCZ with EA0Z).
    const std::vector<int>& flat() const { return flat_; }
    /// ∂(link values flat())/∂(deviation unknowns), internal units (flat().size() × deviationUnknowns()).
    const Eigen::MatrixXd& transform() const { return transform_; }
    /// First unknown of observation r's nuisance parameters.
    int nuisanceStart(int r) const { return nuisanceStart_[r]; }
    const std::vector<int>& deviations() const { return deviations_; }

    /// Solver vector (scaled) → deviation values (internal) written into `set` and the nuisance vector.
    void unpack(const Eigen::VectorXd& x, DeviationSet& set, Eigen::VectorXd& nuisance) const;
    /// Scaled vector from a deviation set and nuisance vector.
    Eigen::VectorXd pack(const DeviationSet& set, const Eigen::VectorXd& nuisance) const;

private:
    const MachineModel* machine_;
    std::vector<int> deviations_;
    std::vector<UnknownInfo> unknowns_;
    std::vector<int> flat_;
    int deviationUnknowns_ = 0;
    Eigen::MatrixXd transform_;
    std::vector<int> nuisanceStart_;
};

/// Parses "EX0C,bXB EA0B;…" (ISO names or aliases, separated by commas, semicolons or spaces) into deviation
/// indices, in machine order without duplicates. "all" selects every deviation. Throws ModelError naming an
/// unknown name and listing the machine's names.
std::vector<int> parseDeviationList(const MachineModel& machine, std::string_view list);

/// Typical size of a coefficient of a component error (internal units per solver unit), see file comment.
double coefficientScale(const MachineModel& machine, const DeviationDef& d, int k);

}  // namespace cnccomp::identification
