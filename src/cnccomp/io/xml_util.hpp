#pragma once
// Shared tinyxml2 helpers for our XML readers (src/cnccomp/io is the only place tinyxml2 is included).
#include <initializer_list>
#include <string>
#include <string_view>
#include <vector>

#include <tinyxml2.h>

#include "cnccomp/geometry.hpp"

namespace cnccomp::io::xml {

/// Loads and parses a file; throws InputError with the parser's line on malformed XML or a missing file.
void load(tinyxml2::XMLDocument& doc, const std::string& path);
/// Root element with the expected name, or InputError.
const tinyxml2::XMLElement& root(const tinyxml2::XMLDocument& doc, const std::string& path, const char* name);

/// Attribute access with file:line errors.
std::string text(const tinyxml2::XMLElement& e, const std::string& path, const char* attr);
std::string textOr(const tinyxml2::XMLElement& e, const char* attr, const std::string& fallback);
bool has(const tinyxml2::XMLElement& e, const char* attr);
double number(const tinyxml2::XMLElement& e, const std::string& path, const char* attr);
double number(const tinyxml2::XMLElement& e, const std::string& path, const char* attr, double fallback);
Vec3 vec3(const tinyxml2::XMLElement& e, const std::string& path, const char* attr, const Vec3& fallback);
bool boolean(const tinyxml2::XMLElement& e, const std::string& path, const char* attr, bool fallback);
std::vector<double> numbers(const tinyxml2::XMLElement& e, const std::string& path, const char* attr);
/// The name of `known` nearest to `word` by edit distance (Levenshtein; case-insensitive), for "did you mean".
std::string nearestName(std::string_view word, std::initializer_list<const char*> known);
/// Throws InputError at the element's line for an attribute not in `known` (a misspelt attribute would otherwise be
/// ignored silently: `lenght-unit="mm"` read every trace 1000x too small), naming the nearest known name.
void allowAttributes(const tinyxml2::XMLElement& e, const std::string& path, std::initializer_list<const char*> known);
/// Throws InputError at `e`'s line: an element not in `known` here, naming the nearest known name.
[[noreturn]] void unknownElement(const tinyxml2::XMLElement& e, const std::string& path, std::initializer_list<const char*> known);
/// Throws InputError at this element's line.
[[noreturn]] void fail(const tinyxml2::XMLElement& e, const std::string& path, const std::string& message);

}  // namespace cnccomp::io::xml
