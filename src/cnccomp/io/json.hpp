#pragma once
// The one JSON reader of cnccomp (the generic backend's deviation and map files, reports read back by tests and
// tools). RFC 8259 text: objects, arrays, strings with every escape (\uXXXX to UTF-8), numbers, true/false/null.
// Stricter than the RFC where a calibration file needs it: a member given twice, a number that is not finite, nesting
// deeper than 200 and text after the value are errors. Every error names the file and the line (InputError); every
// value keeps the line it starts on, so a reader's own checks ("'value' must be a number") name the line too.
//
// Why not nlohmann-json (Debian's nlohmann-json3-dev, as issue review suggested): its document keeps no source
// positions, so a missing member or a value of the wrong type could not be named by line, which every cnccomp reader
// does; its SAX interface does not give positions either. The writers format their numbers themselves.
#include <string>
#include <string_view>
#include <vector>

namespace cnccomp::io {

struct JsonMember;

struct Json {
    enum class Type { Null, Bool, Number, String, Array, Object };
    Type type = Type::Null;
    bool boolean = false;
    double number = 0;
    std::string string;
    std::vector<Json> array;
    std::vector<JsonMember> object;  ///< in file order (a named struct: a pair of an incomplete type breaks clang)
    int line = 0;                                      ///< where the value starts (1-based)

    /// Member of an object, or nullptr.
    const Json* find(std::string_view key) const;
    /// Member of an object; InputError(file, line) when missing or of another type.
    const Json& require(std::string_view key, Type t, const std::string& file) const;
    /// Array of numbers; InputError(file, line) when not.
    std::vector<double> numbers(const std::string& file) const;

    /// Member of an object; ModelError naming the key when absent or not an object (for reading cnccomp's own files).
    const Json& operator[](std::string_view key) const;
    /// Element of an array; ModelError when absent.
    const Json& operator[](size_t i) const;
    bool has(std::string_view key) const { return find(key) != nullptr; }
    /// Number, or NaN for null; ModelError for other types.
    double num() const;
};

struct JsonMember {
    std::string key;
    Json value;
};

/// "null", "a number", … for messages.
const char* jsonTypeName(Json::Type t);

/// Parses JSON text; InputError(source, line, what was expected) on malformed input.
Json parseJson(std::string_view text, const std::string& source = "");
/// Reads and parses a file (a regular file; InputError naming it otherwise).
Json readJsonFile(const std::string& path);

}  // namespace cnccomp::io
