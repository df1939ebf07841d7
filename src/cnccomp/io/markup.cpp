#include "cnccomp/io/markup.hpp"

#include <cmath>

#include <fmt/format.h>

#include "cnccomp/error.hpp"

namespace cnccomp::io {

std::string escapeXml(std::string_view text, std::string_view what) {
    std::string o;
    o.reserve(text.size());
    for (const char c : text) {
        switch (c) {
            case '&': o += "&amp;"; break;
            case '<': o += "&lt;"; break;
            case '>': o += "&gt;"; break;
            case '"': o += "&quot;"; break;
            case '\'': o += "&apos;"; break;
            case '\t': o += "&#9;"; break;
            case '\n': o += "&#10;"; break;
            case '\r': o += "&#13;"; break;
            default:
                if (static_cast<unsigned char>(c) < 0x20)
                    throw ModelError(fmt::format("{} '{}' contains control character {:#04x}, which XML cannot hold", what,
                                                 text, static_cast<unsigned>(static_cast<unsigned char>(c))));
                o += c;
        }
    }
    return o;
}

std::string jsonNumber(double v, int significant) {
    if (!std::isfinite(v)) return "null";
    if (v == 0) return "0";
    return significant > 0 ? fmt::format("{:.{}g}", v, significant) : fmt::format("{}", v);
}

std::string jsonString(std::string_view s) {
    std::string o = "\"";
    for (size_t i = 0; i < s.size(); ++i) {
        const char c = s[i];
        switch (c) {
            case '"': o += "\\\""; break;
            case '\\': o += "\\\\"; break;
            case '\n': o += "\\n"; break;
            case '\r': o += "\\r"; break;
            case '\t': o += "\\t"; break;
            case '/': o += i > 0 && s[i - 1] == '<' ? "\\/" : "/"; break;
            default:
                if (static_cast<unsigned char>(c) < 0x20) o += fmt::format("\\u{:04x}", static_cast<unsigned>(c));
                else o += c;
        }
    }
    return o + "\"";
}

}  // namespace cnccomp::io
