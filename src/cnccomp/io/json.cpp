#include "cnccomp/io/json.hpp"

#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/csv.hpp"
#include "cnccomp/io/text_util.hpp"

namespace cnccomp::io {

const char* jsonTypeName(Json::Type t) {
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

namespace {

class Parser {
public:
    Parser(std::string_view t, const std::string& src) : s(t), source(src) {}

    Json document() {
        Json v = value(0);
        skip();
        if (i != s.size()) fail("end of input after the top-level value");
        return v;
    }

private:
    std::string_view s;
    const std::string& source;
    size_t i = 0;
    int line = 1;

    [[noreturn]] void fail(const std::string& expected) const {
        throw InputError(source, line, fmt::format("malformed JSON: expected {}", expected));
    }
    void skip() {
        while (i < s.size() && (s[i] == ' ' || s[i] == '\n' || s[i] == '\t' || s[i] == '\r')) {
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
        if (depth > 200) fail("less deeply nested values");
        skip();
        if (i >= s.size()) fail("a value");
        Json v;
        v.line = line;
        const char c = s[i];
        if (c == '{') {
            v.type = Json::Type::Object;
            ++i;
            skip();
            if (i < s.size() && s[i] == '}') return ++i, v;
            while (true) {
                skip();
                if (i >= s.size() || s[i] != '"') fail("a quoted member name");
                const int keyLine = line;
                std::string k = string();
                skip();
                if (i >= s.size() || s[i] != ':') fail("':' after a member name");
                ++i;
                for (const auto& kv : v.object)
                    if (kv.key == k) throw InputError(source, keyLine, fmt::format("member '{}' given twice", k));
                v.object.push_back({std::move(k), value(depth + 1)});
                skip();
                if (i < s.size() && s[i] == ',') { ++i; continue; }
                if (i < s.size() && s[i] == '}') { ++i; return v; }
                fail("',' or '}' in an object");
            }
        }
        if (c == '[') {
            v.type = Json::Type::Array;
            ++i;
            skip();
            if (i < s.size() && s[i] == ']') return ++i, v;
            while (true) {
                v.array.push_back(value(depth + 1));
                skip();
                if (i < s.size() && s[i] == ',') { ++i; continue; }
                if (i < s.size() && s[i] == ']') { ++i; return v; }
                fail("',' or ']' in an array");
            }
        }
        if (c == '"') {
            v.type = Json::Type::String;
            v.string = string();
            return v;
        }
        if (literal("true")) return v.type = Json::Type::Bool, v.boolean = true, v;
        if (literal("false")) return v.type = Json::Type::Bool, v;
        if (literal("null")) return v;
        const size_t start = i;
        while (i < s.size() && std::string_view("+-0123456789.eE").find(s[i]) != std::string_view::npos) ++i;
        const auto n = parseNumber(s.substr(start, i - start));
        if (start == i || !n || !std::isfinite(*n)) {
            i = start;
            fail("a value (object, array, string, finite number, true, false or null)");
        }
        v.type = Json::Type::Number;
        v.number = *n;
        return v;
    }
    std::string string() {
        ++i;  // opening quote
        std::string o;
        while (true) {
            if (i >= s.size()) fail("a closing '\"'");
            const char c = s[i++];
            if (c == '"') return o;
            if (c == '\n') {
                --i;
                fail("a closing '\"' before the end of the line");
            }
            if (c != '\\') { o += c; continue; }
            if (i >= s.size()) fail("an escape character");
            const char e = s[i++];
            switch (e) {
                case '"': o += '"'; break;
                case '\\': o += '\\'; break;
                case '/': o += '/'; break;
                case 'n': o += '\n'; break;
                case 't': o += '\t'; break;
                case 'r': o += '\r'; break;
                case 'b': o += '\b'; break;
                case 'f': o += '\f'; break;
                case 'u': {
                    if (i + 4 > s.size()) fail("four hex digits after \\u");
                    unsigned cp = 0;
                    for (int k = 0; k < 4; ++k) {
                        const char h = s[i++];
                        cp <<= 4;
                        if (h >= '0' && h <= '9') cp |= static_cast<unsigned>(h - '0');
                        else if (h >= 'a' && h <= 'f') cp |= static_cast<unsigned>(h - 'a' + 10);
                        else if (h >= 'A' && h <= 'F') cp |= static_cast<unsigned>(h - 'A' + 10);
                        else fail("four hex digits after \\u");
                    }
                    if (cp < 0x80) o += static_cast<char>(cp);
                    else if (cp < 0x800) { o += static_cast<char>(0xC0 | (cp >> 6)); o += static_cast<char>(0x80 | (cp & 0x3F)); }
                    else {
                        o += static_cast<char>(0xE0 | (cp >> 12));
                        o += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
                        o += static_cast<char>(0x80 | (cp & 0x3F));
                    }
                    break;
                }
                default: fail("a valid escape (\\\" \\\\ \\/ \\n \\t \\r \\b \\f \\uXXXX)");
            }
        }
    }
};

}  // namespace

const Json* Json::find(std::string_view key) const {
    if (type != Type::Object) return nullptr;
    for (const auto& [k, v] : object)
        if (k == key) return &v;
    return nullptr;
}

const Json& Json::require(std::string_view key, Type t, const std::string& file) const {
    const Json* v = find(key);
    if (!v) throw InputError(file, line, fmt::format("missing member '{}'", key));
    if (v->type != t) throw InputError(file, v->line, fmt::format("'{}' must be {}", key, jsonTypeName(t)));
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

const Json& Json::operator[](std::string_view key) const {
    if (type != Type::Object) throw ModelError(fmt::format("JSON: '{}' looked up in a value that is not an object", key));
    if (const Json* v = find(key)) return *v;
    throw ModelError(fmt::format("JSON: no member '{}'", key));
}

const Json& Json::operator[](size_t i) const {
    if (type != Type::Array || i >= array.size()) throw ModelError(fmt::format("JSON: no array element {}", i));
    return array[i];
}

double Json::num() const {
    if (type == Type::Null) return std::numeric_limits<double>::quiet_NaN();
    if (type != Type::Number) throw ModelError("JSON: expected a number");
    return number;
}

Json parseJson(std::string_view text, const std::string& source) { return Parser(text, source).document(); }

Json readJsonFile(const std::string& path) {
    requireRegularFile(path);
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(path, 0, "cannot open the file");
    std::ostringstream ss;
    ss << in.rdbuf();
    return parseJson(ss.str(), path);
}

}  // namespace cnccomp::io
