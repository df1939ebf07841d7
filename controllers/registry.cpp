#include <algorithm>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "controllers/backend.hpp"

namespace cnccomp::controllers {
namespace {
std::vector<std::unique_ptr<Backend>>& registry() {
    static std::vector<std::unique_ptr<Backend>> r;
    return r;
}
}  // namespace

RegisterBackend::RegisterBackend(std::unique_ptr<Backend> b) { registry().push_back(std::move(b)); }

std::vector<const Backend*> backends() {
    std::vector<const Backend*> out;
    for (const auto& b : registry()) out.push_back(b.get());
    std::sort(out.begin(), out.end(), [](const Backend* a, const Backend* b) { return a->name() < b->name(); });
    return out;
}

const Backend& backend(std::string_view name) {
    std::string known;
    for (const Backend* b : backends()) {
        if (b->name() == name) return *b;
        known += (known.empty() ? "" : ", ") + std::string(b->name());
    }
    throw ModelError(fmt::format("unknown controller '{}'; known: {}", name, known));
}

namespace {

/// The file each backend's emit() always writes (see the backends' emit()).
struct Signature {
    std::string_view backend;
    std::string_view file;  ///< exact name, or "*.EXT" for any file with that extension
};
constexpr Signature kSignatures[] = {
    {"linuxcnc", "cnccomp.ini"},          {"isg", "volcomp.lis"},        {"generic", "deviations.json"},
    {"heidenhain-tnc", "*.TAB"},          {"fanuc-30i", "CNCCOMP.PRM"},  {"siemens-840d", "CNCCOMP_KINCHAIN.SPF"},
};

bool matches(std::string_view pattern, std::string_view name) {
    if (pattern.substr(0, 1) == "*") return name.size() > pattern.size() - 1 && name.ends_with(pattern.substr(1));
    return name == pattern;
}

}  // namespace

bool Backend::recognizes(const std::vector<OutputFile>& files) const {
    for (const Signature& s : kSignatures)
        if (s.backend == name())
            for (const OutputFile& f : files)
                if (matches(s.file, f.name)) return true;
    return false;
}

const Backend* recognizeBackend(const std::vector<OutputFile>& files) {
    const Backend* found = nullptr;
    std::string all;
    for (const Backend* b : backends()) {
        if (!b->recognizes(files)) continue;
        all += (all.empty() ? "" : ", ") + std::string(b->name());
        if (found) throw ModelError(fmt::format("the files look like the output of several controllers ({}): name one", all));
        found = b;
    }
    return found;
}

}  // namespace cnccomp::controllers
