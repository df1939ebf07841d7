#include "controllers/common/files.hpp"

#include <cmath>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/text_util.hpp"

namespace cnccomp::controllers::common {
using namespace cnccomp::io;

const OutputFile* findFile(const std::vector<OutputFile>& files, std::string_view name) {
    for (const OutputFile& f : files)
        if (f.name == name) return &f;
    return nullptr;
}

const OutputFile& requireFile(const std::vector<OutputFile>& files, std::string_view name, std::string_view backend) {
    if (const OutputFile* f = findFile(files, name)) return *f;
    throw InputError(std::string(name), 0, fmt::format("missing: the {} compensation needs this file", backend));
}

std::vector<TextLine> splitLines(std::string_view text) {
    std::vector<TextLine> out;
    int n = 0;
    while (!text.empty()) {
        const size_t end = text.find('\n');
        std::string_view l = text.substr(0, end);
        if (!l.empty() && l.back() == '\r') l.remove_suffix(1);
        out.push_back({++n, l});
        if (end == std::string_view::npos) break;
        text.remove_prefix(end + 1);
    }
    return out;
}

std::vector<std::string_view> tokens(std::string_view line) {
    std::vector<std::string_view> out;
    size_t i = 0;
    while (i < line.size()) {
        while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
        if (i >= line.size()) break;
        size_t j = i;
        while (j < line.size() && line[j] != ' ' && line[j] != '\t') ++j;
        out.push_back(line.substr(i, j - i));
        i = j;
    }
    return out;
}

double requireNumber(std::string_view token, const std::string& file, int line, std::string_view what) {
    const auto v = parseNumber(token);
    if (!v || !std::isfinite(*v))
        throw InputError(file, line, fmt::format("'{}' is not a finite number; expected {}", token, what));
    return *v;
}

}  // namespace cnccomp::controllers::common
