#include "controllers/linuxcnc/comp_table.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "controllers/common/controller_model.hpp"
#include "controllers/common/files.hpp"

namespace cnccomp::controllers::linuxcnc {
using namespace cnccomp::controllers::common;

double CompTable::trim(double p, int direction) const {
    const size_t n = nominal.size();
    if (n == 0) return 0.0;
    const auto value = [&](size_t i) {
        return direction > 0 ? forward[i] : direction < 0 ? reverse[i] : 0.5 * (forward[i] + reverse[i]);
    };
    if (p < nominal.front()) return value(0);
    if (p >= nominal.back()) return value(n - 1);
    // The entry with nominal <= p < next nominal; trim + slope · (p − nominal), slope from this entry to the next.
    const size_t i = static_cast<size_t>(std::upper_bound(nominal.begin(), nominal.end(), p) - nominal.begin()) - 1;
    const double slope = (value(i + 1) - value(i)) / (nominal[i + 1] - nominal[i]);
    return value(i) + slope * (p - nominal[i]);
}

CompTable fromActualPositions(const CompTable& t) {
    CompTable out = t;
    for (size_t i = 0; i < t.nominal.size(); ++i) {
        out.forward[i] = t.nominal[i] - t.forward[i];
        out.reverse[i] = t.nominal[i] - t.reverse[i];
    }
    return out;
}

std::string formatCompTable(const CompTable& t, const std::string& name) {
    const size_t n = t.nominal.size();
    if (n < 2 || n > static_cast<size_t>(kMaxCompLines))
        throw ModelError(fmt::format("{}: a LinuxCNC compensation table needs 2..{} lines, not {}", name, kMaxCompLines, n));
    if (t.forward.size() != n || t.reverse.size() != n) throw ModelError(fmt::format("{}: columns of unequal length", name));
    std::string out;
    for (size_t i = 0; i < n; ++i) {
        if (!std::isfinite(t.nominal[i]) || !std::isfinite(t.forward[i]) || !std::isfinite(t.reverse[i]))
            throw ModelError(fmt::format("{}: line {} is not finite", name, i + 1));
        if (i > 0 && !(t.nominal[i] > t.nominal[i - 1]))
            throw ModelError(fmt::format("{}: nominals must be strictly increasing (line {})", name, i + 1));
        out += fmt::format("{} {} {}\n", fixed(t.nominal[i], 6), fixed(t.forward[i], 7), fixed(t.reverse[i], 7));
    }
    return out;
}

CompTable parseCompTable(const std::string& text, const std::string& name) {
    CompTable t;
    for (const TextLine& l : splitLines(text)) {
        const auto tok = tokens(l.text);
        if (tok.size() != 3)
            throw InputError(name, l.number,
                             fmt::format("expected three numbers 'nominal forward reverse', got {} fields (LinuxCNC "
                                         "would stop reading the table here)", tok.size()));
        t.nominal.push_back(requireNumber(tok[0], name, l.number, "the nominal position"));
        t.forward.push_back(requireNumber(tok[1], name, l.number, "the forward trim"));
        t.reverse.push_back(requireNumber(tok[2], name, l.number, "the reverse trim"));
        if (t.nominal.size() > 1 && !(t.nominal.back() > t.nominal[t.nominal.size() - 2]))
            throw InputError(name, l.number, "nominal positions must be strictly increasing");
        if (t.nominal.size() > static_cast<size_t>(kMaxCompLines))
            throw InputError(name, l.number, fmt::format("more than {} lines", kMaxCompLines));
    }
    if (t.nominal.size() < 2) throw InputError(name, 0, "a compensation table needs at least two lines");
    return t;
}

}  // namespace cnccomp::controllers::linuxcnc
