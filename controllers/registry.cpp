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

}  // namespace cnccomp::controllers
