#include "cnccomp/map_grid.hpp"

#include <cmath>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/text_util.hpp"

namespace cnccomp {
using namespace cnccomp::io;

long MapGrid::size() const {
    long n = 1;
    for (const GridAxis& a : axes) n *= a.count;
    return n;
}

int MapGrid::find(std::string_view name) const {
    for (int i = 0; i < static_cast<int>(axes.size()); ++i)
        if (axes[i].name == name) return i;
    return -1;
}

void MapGrid::unflatten(long index, long* out) const {
    for (int i = static_cast<int>(axes.size()) - 1; i >= 0; --i) {
        out[i] = index % axes[i].count;
        index /= axes[i].count;
    }
}

MapGrid parseGrid(std::string_view text, const std::string& source, long maxPoints) {
    MapGrid g;
    std::string s(text);
    for (char& c : s)
        if (c == ',' || c == '\t' || c == '\n' || c == '\r') c = ' ';
    size_t pos = 0;
    long total = 1;
    while (pos < s.size()) {
        while (pos < s.size() && s[pos] == ' ') ++pos;
        if (pos >= s.size()) break;
        size_t end = s.find(' ', pos);
        if (end == std::string::npos) end = s.size();
        const std::string item = s.substr(pos, end - pos);
        pos = end;
        const size_t eq = item.find('=');
        if (eq == std::string::npos || eq == 0)
            throw InputError(source, 0, fmt::format("'{}': expected NAME=from:to:step or NAME=value", item));
        GridAxis a;
        a.name = item.substr(0, eq);
        if (g.find(a.name) >= 0) throw InputError(source, 0, fmt::format("axis '{}' given twice", a.name));
        std::vector<std::string_view> parts;
        std::string_view rest = std::string_view(item).substr(eq + 1);
        for (size_t c; (c = rest.find(':')) != std::string_view::npos; rest.remove_prefix(c + 1)) parts.push_back(rest.substr(0, c));
        parts.push_back(rest);
        std::vector<double> v;
        for (std::string_view p : parts) {
            const auto x = parseNumber(p);
            if (!x || !std::isfinite(*x))
                throw InputError(source, 0, fmt::format("'{}': '{}' is not a finite number", item, p));
            v.push_back(*x);
        }
        if (v.size() == 1) {
            a.from = a.to = v[0];
        } else if (v.size() == 3) {
            a.from = v[0];
            a.to = v[1];
            a.step = v[2];
            if (!(a.step > 0)) throw InputError(source, 0, fmt::format("'{}': the step must be positive", item));
            if (!(a.to >= a.from)) throw InputError(source, 0, fmt::format("'{}': 'to' must not be below 'from'", item));
            const double n = (a.to - a.from) / a.step;
            if (n > 1e9) throw InputError(source, 0, fmt::format("'{}': too many points", item));
            const double r = std::round(n);
            if (std::abs(n - r) > 1e-9 * std::max(1.0, n))
                throw InputError(source, 0, fmt::format("'{}': the step does not divide the range", item));
            a.count = static_cast<long>(r) + 1;
        } else {
            throw InputError(source, 0, fmt::format("'{}': expected NAME=from:to:step or NAME=value", item));
        }
        if (total > maxPoints / a.count)
            throw InputError(source, 0, fmt::format("the grid has more than {} points", maxPoints));
        total *= a.count;
        g.axes.push_back(std::move(a));
    }
    if (g.axes.empty()) throw InputError(source, 0, "empty grid");
    return g;
}

}  // namespace cnccomp
