#pragma once
// The HTML report of the circles of the linear axes (identify on a plan of <circle> runs): the polar plot of every
// run's passes as measured and with the identified diagnostics removed, the ISO 230-4 table (G, F, mean radius, H per
// run; G, F per pass), the test conditions, the diagnostics of every run ranked by their share of the circularity
// (value, unit, 95 % interval, share, model) with the unidentified ones and their confounded groups, and the
// deviations written into the deviation set.
#include <string>
#include <utility>
#include <vector>

#include "cnccomp/linear_circle_identify.hpp"
#include "app/report/report_data.hpp"

namespace cnccomp::app::report {

ReportData linearCircleReportData(const std::string& machine, const LinearCircleIdentification& id,
                                  std::vector<std::pair<std::string, std::string>> facts);

}  // namespace cnccomp::app::report
