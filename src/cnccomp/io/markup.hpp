#pragma once
// Escaping of text written into XML, SVG, HTML and JSON, so that names taken from inputs (a machine called "A&B", a run
// called "<x>") are written as they are and read back the same.
#include <string>
#include <string_view>

namespace cnccomp {

/// & < > " ' as entities; tab, line feed and carriage return as character references (so that attribute values
/// keep them: XML parsers normalise raw ones to spaces). Other control characters cannot appear in XML 1.0:
/// ModelError naming `what` (e.g. "machine name").
std::string escapeXml(std::string_view text, std::string_view what = "text");

/// JSON string literal: quotes, backslashes and control characters escaped; "</" written as "<\/" so that the text can
/// also sit inside an HTML <script> element.
std::string jsonString(std::string_view s);

}  // namespace cnccomp
