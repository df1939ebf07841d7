#include "cnccomp/io/text_util.hpp"

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <unistd.h>

#include <fmt/format.h>

#include "cnccomp/error.hpp"

namespace cnccomp {

std::string_view trim(std::string_view s) {
    while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == '\r' || s.front() == '\n')) s.remove_prefix(1);
    while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r' || s.back() == '\n')) s.remove_suffix(1);
    return s;
}

std::optional<double> parseNumber(std::string_view s) {
    s = trim(s);
    if (s.empty()) return std::nullopt;
    if (s == "inf" || s == "+inf") return HUGE_VAL;
    if (s == "-inf") return -HUGE_VAL;
    if (s.front() == '+') s.remove_prefix(1);
    double v = 0.0;
    const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
    if (r.ec != std::errc() || r.ptr != s.data() + s.size() || std::isnan(v)) return std::nullopt;
    return v;
}

void refuseToOverwrite(const std::string& output, std::initializer_list<std::string> inputs) {
    namespace fs = std::filesystem;
    std::error_code ec;
    for (const std::string& in : inputs) {
        if (in.empty()) continue;
        if (fs::exists(output, ec) && fs::exists(in, ec) && fs::equivalent(output, in, ec))
            throw InputError(output, 0, fmt::format("refusing to overwrite the input file '{}'", in));
    }
}

void writeFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write) {
    namespace fs = std::filesystem;
    const fs::path target(path);
    const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
    std::error_code ec;
    if (!fs::is_directory(dir, ec)) throw InputError(path, 0, "output folder does not exist");
    const fs::path tmp = dir / fmt::format(".{}.tmp{}", target.filename().string(), ::getpid());
    try {
        {
            std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
            if (!out) throw InputError(path, 0, "cannot create output file");
            write(out);
            out.flush();
            if (!out) throw InputError(path, 0, "write failed");
        }
        fs::rename(tmp, target);
    } catch (...) {
        fs::remove(tmp, ec);
        throw;
    }
}

}  // namespace cnccomp
