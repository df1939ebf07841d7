#include "cnccomp/io/xml_util.hpp"

#include <algorithm>
#include <cctype>
#include <climits>
#include <cmath>
#include <cstdint>
#include <vector>
#include <sstream>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/csv.hpp"
#include "cnccomp/io/text_util.hpp"

namespace cnccomp::io::xml {

void load(tinyxml2::XMLDocument& doc, const std::string& path) {
    requireRegularFile(path);  // a folder or a FIFO is named, never opened
    const tinyxml2::XMLError err = doc.LoadFile(path.c_str());
    if (err == tinyxml2::XML_ERROR_FILE_NOT_FOUND || err == tinyxml2::XML_ERROR_FILE_COULD_NOT_BE_OPENED)
        throw InputError(path, 0, "cannot open file");
    if (err != tinyxml2::XML_SUCCESS)
        throw InputError(path, doc.ErrorLineNum(), fmt::format("malformed XML: {}", doc.ErrorStr()));
}

const tinyxml2::XMLElement& root(const tinyxml2::XMLDocument& doc, const std::string& path, const char* name) {
    const tinyxml2::XMLElement* r = doc.RootElement();
    if (!r) throw InputError(path, 1, fmt::format("expected a <{}> element", name));
    if (std::string(r->Name()) != name)
        throw InputError(path, r->GetLineNum(), fmt::format("expected root element <{}>, found <{}>", name, r->Name()));
    return *r;
}

void fail(const tinyxml2::XMLElement& e, const std::string& path, const std::string& message) {
    throw InputError(path, e.GetLineNum(), fmt::format("<{}>: {}", e.Name(), message));
}

std::string nearestName(std::string_view word, std::initializer_list<const char*> known) {
    const auto low = [](char c) { return static_cast<char>(std::tolower(static_cast<unsigned char>(c))); };
    std::string best;
    size_t bestDistance = SIZE_MAX;
    for (const char* k : known) {
        const std::string_view b(k);
        std::vector<size_t> row(b.size() + 1);
        for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
        for (size_t i = 1; i <= word.size(); ++i) {
            size_t diagonal = row[0];
            row[0] = i;
            for (size_t j = 1; j <= b.size(); ++j) {
                const size_t up = row[j];
                row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (low(word[i - 1]) == low(b[j - 1]) ? 0 : 1)});
                diagonal = up;
            }
        }
        if (row[b.size()] < bestDistance) {
            bestDistance = row[b.size()];
            best = k;
        }
    }
    return best;
}

namespace {
std::string listOf(std::initializer_list<const char*> known) {
    std::string s;
    for (const char* k : known) s += (s.empty() ? "" : ", ") + std::string(k);
    return s;
}
}  // namespace

void allowAttributes(const tinyxml2::XMLElement& e, const std::string& path, std::initializer_list<const char*> known) {
    for (const tinyxml2::XMLAttribute* a = e.FirstAttribute(); a; a = a->Next()) {
        const std::string_view name = a->Name();
        bool ok = false;
        for (const char* k : known) ok = ok || name == k;
        if (ok) continue;
        if (known.size() == 0) fail(e, path, fmt::format("unknown attribute '{}'; this element takes none", name));
        fail(e, path, fmt::format("unknown attribute '{}'; did you mean '{}'? (known: {})", name, nearestName(name, known),
                                  listOf(known)));
    }
}

void unknownElement(const tinyxml2::XMLElement& e, const std::string& path, std::initializer_list<const char*> known) {
    throw InputError(path, e.GetLineNum(), fmt::format("unknown element <{}>; did you mean <{}>? (expected here: {})", e.Name(),
                                                       nearestName(e.Name(), known), listOf(known)));
}

bool has(const tinyxml2::XMLElement& e, const char* attr) { return e.Attribute(attr) != nullptr; }

std::string text(const tinyxml2::XMLElement& e, const std::string& path, const char* attr) {
    const char* v = e.Attribute(attr);
    if (!v) fail(e, path, fmt::format("missing attribute '{}'", attr));
    return v;
}

std::string textOr(const tinyxml2::XMLElement& e, const char* attr, const std::string& fallback) {
    const char* v = e.Attribute(attr);
    return v ? std::string(v) : fallback;
}

double number(const tinyxml2::XMLElement& e, const std::string& path, const char* attr) {
    const std::string s = text(e, path, attr);
    const auto v = parseNumber(s);
    if (!v) fail(e, path, fmt::format("attribute '{}' = '{}' is not a number", attr, s));
    return *v;
}

double number(const tinyxml2::XMLElement& e, const std::string& path, const char* attr, double fallback) {
    return has(e, attr) ? number(e, path, attr) : fallback;
}

std::vector<double> numbers(const tinyxml2::XMLElement& e, const std::string& path, const char* attr) {
    std::istringstream in(text(e, path, attr));
    std::vector<double> out;
    std::string tok;
    while (in >> tok) {
        const auto v = parseNumber(tok);
        if (!v || !std::isfinite(*v)) fail(e, path, fmt::format("attribute '{}': '{}' is not a finite number", attr, tok));
        out.push_back(*v);
    }
    return out;
}

Vec3 vec3(const tinyxml2::XMLElement& e, const std::string& path, const char* attr, const Vec3& fallback) {
    if (!has(e, attr)) return fallback;
    const auto v = numbers(e, path, attr);
    if (v.size() != 3) fail(e, path, fmt::format("attribute '{}' needs three numbers", attr));
    return Vec3(v[0], v[1], v[2]);
}

bool boolean(const tinyxml2::XMLElement& e, const std::string& path, const char* attr, bool fallback) {
    if (!has(e, attr)) return fallback;
    const std::string s = text(e, path, attr);
    if (s == "true" || s == "1" || s == "yes") return true;
    if (s == "false" || s == "0" || s == "no") return false;
    fail(e, path, fmt::format("attribute '{}' = '{}' is not true/false", attr, s));
}

}  // namespace cnccomp::io::xml
