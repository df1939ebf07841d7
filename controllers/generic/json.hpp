#pragma once
// A small JSON reader and writer helpers for the generic backend's own files (no JSON library among the project's
// Debian dependencies). Reads objects, arrays, strings (\" \\ \/ \n \t \u00XX escapes), numbers, true/false/null;
// errors name the file and line.
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace cnccomp::controllers::generic {

struct Json {
    enum class Type { Null, Bool, Number, String, Array, Object };
    Type type = Type::Null;
    bool boolean = false;
    double number = 0;
    std::string string;
    std::vector<Json> array;
    std::vector<std::pair<std::string, Json>> object;
    int line = 0;  ///< where the value starts

    /// Member of an object, or nullptr.
    const Json* find(std::string_view key) const;
    /// Member of an object; InputError(file, line) when missing or of another type.
    const Json& require(std::string_view key, Type t, const std::string& file) const;
    /// Array of numbers; InputError when not.
    std::vector<double> numbers(const std::string& file) const;
};

Json parseJson(std::string_view text, const std::string& file);

/// JSON text of a string (quoted, escaped).
std::string jsonString(std::string_view s);
/// Shortest round-trip text of a finite number.
std::string jsonNumber(double v);
/// "[a, b, …]" of numbers.
std::string jsonNumbers(const std::vector<double>& v);

}  // namespace cnccomp::controllers::generic
