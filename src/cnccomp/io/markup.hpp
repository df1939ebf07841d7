#pragma once
// Escaping of text written into XML, SVG, HTML and JSON, so that names taken from inputs (a machine called "A&B", a run
// called "<x>") are written as they are and read back the same.
#include <string>
#include <string_view>

namespace cnccomp::io {

/// & < > " ' as entities; tab, line feed and carriage return as character references (so that attribute values
/// keep them: XML parsers normalise raw ones to spaces). Other control characters cannot appear in XML 1.0:
/// ModelError naming `what` (e.g. "machine name").
std::string escapeXml(std::string_view text, std::string_view what = "text");

/// JSON string literal: quotes, backslashes and control characters escaped; "</" written as "<\/" so that the text can
/// also sit inside an HTML <script> element.
std::string jsonString(std::string_view s);

/// A number as JSON text, the one writer of every JSON file cnccomp writes: with `significant` = 0 the shortest text that
/// reads back to the same double, else that many significant digits (printf %.<n>g); zero of either sign as 0; NaN and
/// infinities, which JSON cannot hold, as null (a writer that must refuse them checks before: the generic backend).
std::string jsonNumber(double v, int significant = 0);

}  // namespace cnccomp::io
