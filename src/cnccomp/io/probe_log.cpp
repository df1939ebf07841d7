#include "cnccomp/io/probe_log.hpp"

#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/text_util.hpp"

namespace cnccomp::io {
using namespace cnccomp::measurement;
namespace {

constexpr const char* kAxes[] = {"X", "Y", "Z", "A", "B", "C"};

/// A number as the controllers print it: "12.5", "-0.000000", "3." (Fanuc DPRNT), "+1.5".
std::optional<double> logNumber(std::string_view w) {
    std::string s(w);
    if (!s.empty() && s.front() == '+') s.erase(s.begin());
    if (!s.empty() && s.back() == '.') s.pop_back();
    if (s.empty()) return std::nullopt;
    const auto v = parseNumber(s);
    if (!v || !std::isfinite(*v)) return std::nullopt;
    return v;
}

}  // namespace

ProbeLog parseProbeLog(const std::string& text, const std::string& source, const MachineModel& m) {
    ProbeLog log;
    log.file = source;
    std::istringstream in(text);
    std::string raw;
    int line = 0;
    while (std::getline(in, raw)) {
        ++line;
        std::istringstream words{std::string(trim(raw))};
        std::vector<std::string> w;
        for (std::string s; words >> s;) w.push_back(s);
        if (w.empty() || w[0] != "TOUCH") continue;
        if (w.size() != 10 && w.size() != 9)
            throw InputError(source, line,
                             fmt::format("a TOUCH line has {} words; expected TOUCH <pose> <touch> <flag> X Y Z A B C (10) "
                                         "or without the flag (9)",
                                         w.size()));
        ProbeTouch t;
        t.line = line;
        const auto whole = [&](size_t i, const char* what) {
            const auto v = logNumber(w[i]);
            if (!v || *v < 0 || *v != std::floor(*v) || *v > 1e6)
                throw InputError(source, line, fmt::format("TOUCH {} '{}' is not a whole number from 0", what, w[i]));
            return static_cast<int>(*v);
        };
        t.pose = whole(1, "pose");
        t.touch = whole(2, "touch");
        size_t first = 3;
        if (w.size() == 10) {
            const auto f = logNumber(w[3]);
            if (!f || (*f != 0 && *f != 1))
                throw InputError(source, line, fmt::format("TOUCH flag '{}' is not 0 (missed) or 1 (triggered)", w[3]));
            t.triggered = static_cast<int>(*f);
            first = 4;
        }
        t.q = AxisVector::Constant(m.axisCount(), std::numeric_limits<double>::quiet_NaN());
        for (int a = 0; a < 6; ++a) {
            const std::string& word = w[first + static_cast<size_t>(a)];
            const auto v = logNumber(word);
            if (!v) throw InputError(source, line, fmt::format("TOUCH {} value '{}' is not a number", kAxes[a], word));
            const int i = m.axisIndex(kAxes[a]);
            if (i >= 0) t.q[i] = m.axisLink(i).kind == AxisKind::Rotary ? *v * kDeg : *v;
        }
        t.q = m.fromController(t.q);  // the programs' coordinates are the controller's machine coordinates
        log.touches.push_back(t);
    }
    if (log.touches.empty())
        throw InputError(source, line, "no TOUCH line (expected TOUCH <pose> <touch> <flag> X Y Z A B C, one per touch)");
    return log;
}

ProbeLog readProbeLog(const std::string& path, const MachineModel& m) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(path, 0, "cannot read the probe result file");
    std::ostringstream s;
    s << in.rdbuf();
    return parseProbeLog(s.str(), path, m);
}

std::string formatProbeLog(const ProbeLog& log, const MachineModel& m, int decimals) {
    std::string out;
    for (const ProbeTouch& t : log.touches) {
        out += fmt::format("TOUCH {} {} {:.{}f}", t.pose, t.touch, t.triggered > 0 ? 1.0 : 0.0, decimals);
        const AxisVector c = m.toController(t.q);
        for (const char* a : kAxes) {
            const int i = m.axisIndex(a);
            double v = i >= 0 && i < c.size() ? c[i] : 0.0;
            if (i >= 0 && m.axisLink(i).kind == AxisKind::Rotary) v /= kDeg;
            out += fmt::format(" {:.{}f}", v, decimals);
        }
        out += '\n';
    }
    return out;
}

void writeProbeLog(const std::string& path, const ProbeLog& log, const MachineModel& m, int decimals) {
    const std::string text = formatProbeLog(log, m, decimals);
    writeFileAtomically(path, [&](std::ostream& o) { o << text; });
}

}  // namespace cnccomp::io
