#include "app/identify_registry.hpp"

#include <fmt/format.h>

#include "cnccomp/error.hpp"

namespace cnccomp::app {
using namespace cnccomp::identification;

const std::vector<IdentificationMethod>& identificationMethods() {
    static const std::vector<IdentificationMethod> all = [] {
        std::vector<IdentificationMethod> v = rotaryAxisMethods();
        v.push_back(linearCircleMethod());
        return v;
    }();
    return all;
}

namespace {

std::string registeredNames() {
    std::string names;
    for (const IdentificationMethod& m : identificationMethods()) names += (names.empty() ? "" : ", ") + m.name;
    return names;
}

}  // namespace

const IdentificationMethod& identificationMethod(std::string_view name) {
    for (const IdentificationMethod& m : identificationMethods())
        if (m.name == name) return m;
    throw ModelError(fmt::format("unknown identification method '{}'; registered: {}", name, registeredNames()));
}

const IdentificationMethod& identificationMethodFor(PlanMethod kind) {
    for (const IdentificationMethod& m : identificationMethods())
        for (PlanMethod k : m.serves)
            if (k == kind) return m;
    throw ModelError(fmt::format("no identification method serves plans of kind '{}'; registered: {}",
                                 planMethodName(kind), registeredNames()));
}

}  // namespace cnccomp::app
