#pragma once
// Identification report as JSON (schema "cnccomp-identification-report/1"): solver outcome, residual RMS per run,
// singular values, parameters with 95 % intervals (display units: um, arcsec), unidentified names, identifiable
// combinations and unobservable directions, covariance (internal units: mm, rad). NaN is written as null.
// A small JSON reader (parseJson) reads it back for tests and tools.
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "cnccomp/identification/report.hpp"

namespace cnccomp {

std::string formatReportJson(const IdentificationReport& report);
/// Writes atomically (never a half file).
void writeReportJson(const std::string& path, const IdentificationReport& report);

/// A parsed JSON value.
struct JsonValue {
    enum class Type { Null, Bool, Number, String, Array, Object } type = Type::Null;
    bool boolean = false;
    double number = 0;
    std::string string;
    std::vector<JsonValue> array;
    std::vector<std::pair<std::string, JsonValue>> object;  ///< in file order

    /// Member of an object; throws ModelError naming the key when absent or not an object.
    const JsonValue& operator[](const std::string& key) const;
    const JsonValue& operator[](size_t i) const;
    bool has(const std::string& key) const;
    /// Number, or NaN for null; throws ModelError for other types.
    double num() const;
};

/// Parses JSON text; throws InputError(source, line, what was expected) on malformed input.
JsonValue parseJson(const std::string& text, const std::string& source = "");
JsonValue readJsonFile(const std::string& path);

}  // namespace cnccomp
