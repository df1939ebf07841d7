#pragma once
#include <iosfwd>
// Eccentricity tables: CSV `test,LB_mm,RB_mm,RC_mm,ZC_mm,ex_um,ey_um,ez_um`; empty cells allowed.
#include <string>
#include <vector>

#include "cnccomp/eccentricity.hpp"

namespace cnccomp::io {

std::vector<EccentricityRow> readEccentricityCsv(const std::string& path);
void writeEccentricityCsv(const std::string& path, const std::vector<EccentricityRow>& rows);
/// The same CSV written to a stream (for outputs staged together, io/output_set.hpp).
void writeEccentricityCsv(std::ostream& out, const std::vector<EccentricityRow>& rows);

}  // namespace cnccomp::io
