#include "controllers/generic/json_text.hpp"

#include <cmath>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/markup.hpp"

namespace cnccomp::controllers::generic {

std::string jsonNumber(double v) {
    if (!std::isfinite(v)) throw ModelError("JSON cannot hold a number that is not finite");
    return cnccomp::io::jsonNumber(v);
}

std::string jsonNumbers(const std::vector<double>& v) {
    std::string out = "[";
    for (size_t i = 0; i < v.size(); ++i) out += (i ? ", " : "") + jsonNumber(v[i]);
    return out + "]";
}

}  // namespace cnccomp::controllers::generic
