#pragma once
// Identification report as JSON (schema "cnccomp-identification-report/1"): solver outcome, residual RMS per run,
// singular values, parameters with 95 % intervals (display units: um, arcsec), unidentified names, identifiable
// combinations and unobservable directions, covariance (internal units: mm, rad). NaN is written as null.
// The one JSON reader (io/json.hpp) reads it back for tests and tools.
#include <string>

#include "cnccomp/identification/report.hpp"

namespace cnccomp::io {

std::string formatReportJson(const identification::IdentificationReport& report);
/// Writes atomically (never a half file).
void writeReportJson(const std::string& path, const identification::IdentificationReport& report);

}  // namespace cnccomp::io
