#pragma once
// Measurement plans: <plan machine="..."> with one <run> element per ball-bar run.
#include <string>
#include <vector>

#include "cnccomp/ballbar.hpp"

namespace cnccomp {

struct MeasurementPlan {
    std::string machine;      ///< machine name the plan was made for (may be empty)
    std::string description;
    std::vector<BallbarRun> runs;
};

/// Attributes of <run>: name, test (B-X … B-axial), LB RB RC ZC (mm), start end step (deg),
/// tool-ball-offset / work-ball-offset ("x y z" mm),
/// estimate-mounting (none|tool|work|both: mounting offsets as nuisance parameters), head-axis / table-axis (default B / C).
MeasurementPlan readPlanXml(const std::string& path);
void writePlanXml(const std::string& path, const MeasurementPlan& plan);
std::string formatPlanXml(const MeasurementPlan& plan);

}  // namespace cnccomp
