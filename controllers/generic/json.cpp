#include "controllers/generic/json.hpp"

#include "cnccomp/io/markup.hpp"

#include <cmath>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/text_util.hpp"

namespace cnccomp::controllers::generic {
namespace {

const char* typeName(Json::Type t) {
    switch (t) {
        case Json::Type::Null: return "null";
        case Json::Type::Bool: return "a boolean";
        case Json::Type::Number: return "a number";
        case Json::Type::String: return "a string";
        case Json::Type::Array: return "an array";
        case Json::Type::Object: return "an object";
    }
    return "?";
}

struct Parser {
    std::string_view s;
    const std::string& file;
    size_t i = 0;
    int line = 1;

    [[noreturn]] void fail(const std::string& msg) const { throw InputError(file, line, msg); }
    void skip() {
        while (i < s.size() && (s[i] == ' ' || s[i] == '\t' || s[i] == '\r' || s[i] == '\n')) {
            if (s[i] == '\n') ++line;
            ++i;
        }
    }
    bool literal(std::string_view w) {
        if (s.substr(i, w.size()) != w) return false;
        i += w.size();
        return true;
    }
    Json value(int depth) {
        if (depth > 64) fail("nesting too deep");
        skip();
        if (i >= s.size()) fail("unexpected end of the text");
        Json v;
        v.line = line;
        const char c = s[i];
        if (c == '{') {
            v.type = Json::Type::Object;
            ++i;
            skip();
            if (i < s.size() && s[i] == '}') return ++i, v;
            for (;;) {
                skip();
                if (i >= s.size() || s[i] != '"') fail("expected a member name in quotes");
                std::string key = str();
                skip();
                if (i >= s.size() || s[i] != ':') fail("expected ':' after a member name");
                ++i;
                for (const auto& [k, x] : v.object)
                    if (k == key) fail(fmt::format("member '{}' given twice", key));
                v.object.emplace_back(std::move(key), value(depth + 1));
                skip();
                if (i < s.size() && s[i] == ',') { ++i; continue; }
                if (i < s.size() && s[i] == '}') { ++i; return v; }
                fail("expected ',' or '}' in an object");
            }
        }
        if (c == '[') {
            v.type = Json::Type::Array;
            ++i;
            skip();
            if (i < s.size() && s[i] == ']') return ++i, v;
            for (;;) {
                v.array.push_back(value(depth + 1));
                skip();
                if (i < s.size() && s[i] == ',') { ++i; continue; }
                if (i < s.size() && s[i] == ']') { ++i; return v; }
                fail("expected ',' or ']' in an array");
            }
        }
        if (c == '"') {
            v.type = Json::Type::String;
            v.string = str();
            return v;
        }
        if (literal("true")) return v.type = Json::Type::Bool, v.boolean = true, v;
        if (literal("false")) return v.type = Json::Type::Bool, v;
        if (literal("null")) return v;
        size_t j = i;
        while (j < s.size() && std::string_view("+-0123456789.eE").find(s[j]) != std::string_view::npos) ++j;
        const auto n = parseNumber(s.substr(i, j - i));
        if (j == i || !n || !std::isfinite(*n)) fail(fmt::format("expected a value, got '{}'", s.substr(i, std::max<size_t>(1, j - i))));
        i = j;
        v.type = Json::Type::Number;
        v.number = *n;
        return v;
    }
    std::string str() {
        ++i;  // opening quote
        std::string out;
        while (i < s.size() && s[i] != '"') {
            char c = s[i++];
            if (c == '\n') fail("line break inside a string");
            if (c == '\\') {
                if (i >= s.size()) break;
                const char e = s[i++];
                if (e == 'n') c = '\n';
                else if (e == 't') c = '\t';
                else if (e == '"' || e == '\\' || e == '/') c = e;
                else if (e == 'u' && i + 4 <= s.size()) {
                    const std::string hex(s.substr(i, 4));
                    i += 4;
                    const unsigned long u = std::strtoul(hex.c_str(), nullptr, 16);
                    if (u > 0x7f) fail("only \\u00XX escapes of ASCII characters are read");
                    c = static_cast<char>(u);
                } else {
                    fail("unknown escape in a string");
                }
            }
            out += c;
        }
        if (i >= s.size()) fail("unterminated string");
        ++i;
        return out;
    }
};

}  // namespace

const Json* Json::find(std::string_view key) const {
    for (const auto& [k, v] : object)
        if (k == key) return &v;
    return nullptr;
}

const Json& Json::require(std::string_view key, Type t, const std::string& file) const {
    const Json* v = find(key);
    if (!v) throw InputError(file, line, fmt::format("missing member '{}'", key));
    if (v->type != t) throw InputError(file, v->line, fmt::format("'{}' must be {}", key, typeName(t)));
    return *v;
}

std::vector<double> Json::numbers(const std::string& file) const {
    if (type != Type::Array) throw InputError(file, line, "expected an array of numbers");
    std::vector<double> out;
    for (const Json& v : array) {
        if (v.type != Type::Number) throw InputError(file, v.line, "expected a number");
        out.push_back(v.number);
    }
    return out;
}

Json parseJson(std::string_view text, const std::string& file) {
    Parser p{text, file};
    Json v = p.value(0);
    p.skip();
    if (p.i != text.size()) p.fail("text after the JSON value");
    return v;
}

std::string jsonString(std::string_view s) { return cnccomp::jsonString(s); }

std::string jsonNumber(double v) {
    if (!std::isfinite(v)) throw ModelError("JSON cannot hold a number that is not finite");
    if (v == 0) return "0";
    return fmt::format("{}", v);
}

std::string jsonNumbers(const std::vector<double>& v) {
    std::string out = "[";
    for (size_t i = 0; i < v.size(); ++i) out += (i ? ", " : "") + jsonNumber(v[i]);
    return out + "]";
}

}  // namespace cnccomp::controllers::generic
