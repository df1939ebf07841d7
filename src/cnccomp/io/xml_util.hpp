#pragma once
// Shared tinyxml2 helpers for our XML readers (src/cnccomp/io is the only place tinyxml2 is included).
#include <string>
#include <vector>

#include <tinyxml2.h>

#include "cnccomp/geometry.hpp"

namespace cnccomp::xml {

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
/// Throws InputError at this element's line.
[[noreturn]] void fail(const tinyxml2::XMLElement& e, const std::string& path, const std::string& message);

}  // namespace cnccomp::xml
