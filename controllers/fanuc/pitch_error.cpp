#include "controllers/fanuc/pitch_error.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "controllers/common/axis_table.hpp"
#include "controllers/common/controller_model.hpp"

namespace cnccomp::controllers::fanuc {
using namespace cnccomp::controllers::common;

double PitchTable::correction(double x, double unit) const {
    // Section boundaries j = 0..n at machine positions (negative - 1 - reference + j) x interval; the section that ends
    // at boundary j belongs to point negative - 1 + j. The absolute correction is 0 at the reference position and
    // changes by that point's data across its section (B-63980EN p.100).
    const int n = positive - negative + 1;
    if (n < 1 || static_cast<int>(data.size()) != n || !(interval > 0)) return 0.0;
    const int r = reference - negative + 1;  // boundary at machine position 0
    if (r < 0 || r > n) return 0.0;
    std::vector<double> a(static_cast<size_t>(n) + 1, 0.0);
    const double u = unit * magnification;
    for (int j = r + 1; j <= n; ++j) a[j] = a[j - 1] + static_cast<double>(data[j - 1]) * u;
    for (int j = r - 1; j >= 0; --j) a[j] = a[j + 1] - static_cast<double>(data[j]) * u;
    const double lo = (negative - 1 - reference) * interval, hi = (positive - reference) * interval;
    if (rotaryType) {  // one revolution from the reference position
        x = std::fmod(x, 360.0);
        if (x < 0) x += 360.0;
    }
    if (x <= lo) return a.front();
    if (x >= hi) return a.back();
    const double t = (x - lo) / interval;
    const int j = std::min(static_cast<int>(std::floor(t)), n - 1);
    return a[j] + (a[j + 1] - a[j]) * (t - j);
}

namespace {

/// Is this component error the positioning error of its own axis? Returns +1/-1 (sign along the axis) or 0.
int ownAxis(const DeviationDef& def, const Link& l) {
    const bool rotaryComponent = def.component >= 3;
    if ((l.kind == AxisKind::Rotary) != rotaryComponent) return 0;
    const double along = Vec3::Unit(def.component % 3).dot(l.direction);
    if (std::abs(std::abs(along) - 1.0) > 1e-9) return 0;
    return along > 0 ? 1 : -1;
}

}  // namespace

double positioningError(const MachineModel& m, const Eigen::VectorXd& values, int axis, double command) {
    const Link& l = m.axisLink(axis);
    double e = 0;
    for (const DeviationDef& def : m.deviations) {
        if (def.kind != DeviationKind::Component || m.chain(def.side).links[def.link].axisIndex != axis) continue;
        if (const int sign = ownAxis(def, l)) e += sign * def.basis.evaluate(command, values.data() + def.offset, l.modulo);
    }
    return e;
}

PitchPlan pitchFromDeviations(const MachineModel& m, const DeviationSet& d, const PitchOptions& o) {
    PitchPlan plan;
    std::map<int, std::vector<int>> byAxis;
    for (size_t di = 0; di < m.deviations.size(); ++di) {
        const DeviationDef& def = m.deviations[di];
        if (!d.present[di] || def.kind != DeviationKind::Component) continue;
        const Link& l = m.chain(def.side).links[def.link];
        if (ownAxis(def, l) == 0) {
            plan.notCompensated.push_back(
                {def.name, l.kind == AxisKind::Linear && def.component < 3
                               ? "straightness (cross-axis) error: the 30i straightness compensation parameters are not "
                                 "public [G]; not written"
                               : "angular / radial error motion: needs 3-D error compensation (parameter numbers not "
                                 "public [G]); not written"});
            continue;
        }
        byAxis[l.axisIndex].push_back(static_cast<int>(di));
    }
    int base = 0;
    for (int a : controllerAxisOrder(m)) {
        const auto it = byAxis.find(a);
        if (it == byAxis.end()) continue;
        const Link& l = m.axisLink(a);
        const auto reject = [&](const std::string& why) {
            for (int di : it->second) plan.notCompensated.push_back({m.deviations[di].name, why});
        };
        EquidistantTable grid;
        try {
            grid = gridOverTravel(l, o.maxIntervals + 1);
        } catch (const ModelError& e) {
            reject(e.what());
            continue;
        }
        const double toFile = l.kind == AxisKind::Rotary ? 1.0 / kDeg : 1.0;
        const auto err = [&](double pos) { return positioningError(m, d.values, a, commandOf(l, pos)) * toFile; };
        if (grid.modulo && std::abs(err(0.0) - err(360.0)) > 1e-9) {
            reject("not periodic over one revolution: a rotary-axis pitch table must sum to zero");
            continue;
        }
        // Boundaries of the sections (grid positions, machine coordinates); point numbers as the parameter manual
        // derives them: 3621 = 3620 - (negative stroke / interval) + 1, 3622 = 3620 + positive stroke / interval.
        const int nb = static_cast<int>(grid.values.size());
        const int r = static_cast<int>(std::lround(-grid.min / grid.step));
        const double e0 = err(0.0);
        std::vector<double> c(nb);
        for (int k = 0; k < nb; ++k) c[k] = -(err(grid.min + grid.step * k) - e0);
        double maxStep = 0;
        for (int k = 1; k < nb; ++k) maxStep = std::max(maxStep, std::abs(c[k] - c[k - 1]) / o.unit);
        PitchTable t;
        t.axis = a;
        t.interval = grid.step;
        t.rotaryType = grid.modulo;
        if (t.rotaryType) {
            t.reference = t.negative = base;
            t.positive = base + nb - 1;
        } else {
            t.reference = base + std::max(r - 1, 0);
            t.negative = t.reference - r + 1;
            t.positive = t.negative + nb - 2;
        }
        for (t.magnification = std::max(1, static_cast<int>(std::ceil(maxStep / o.maxData)));; ++t.magnification) {
            if (t.magnification > o.maxMagnification)
                throw ModelError(fmt::format("fanuc-30i: pitch error of axis {} changes by {:.1f} detection units per "
                                             "interval; even magnification {} exceeds the data range +-{}",
                                             l.name, maxStep, o.maxMagnification, o.maxData));
            const double u = o.unit * t.magnification;
            // Point negative + s holds the section from boundary s (rotary: s - 1) to the next; rounding the absolute
            // values keeps the sum exact (a revolution sums to zero).
            t.data.assign(static_cast<size_t>(t.positive - t.negative + 1), 0);
            bool fits = true;
            const int first = t.rotaryType ? 1 : 0;
            for (int s = 0; s + 1 < nb; ++s) {
                const long v = std::lround(c[s + 1] / u) - std::lround(c[s] / u);
                t.data[static_cast<size_t>(s + first)] = v;
                fits = fits && std::abs(v) <= o.maxData;
            }
            if (t.rotaryType) t.data.front() = t.data.back();  // 3620 holds the value of 3622 (B-63980EN p.100)
            if (fits) break;
        }
        base = t.positive + 1;
        if (base > o.maxPoints)
            throw ModelError(fmt::format("fanuc-30i: the pitch error tables need {} compensation points; the control holds {}",
                                         base, o.maxPoints));
        const std::string axisWord = fmt::format("A{}", controllerAxisNumber(m, a));
        const bool constant = std::abs(e0) > o.unit / 2;
        const bool linear = l.kind == AxisKind::Linear;
        for (int di : it->second)
            plan.compensated.push_back({m.deviations[di].name,
                                        fmt::format("pitch error compensation of {} ({}): points {}..{}, reference {}, "
                                                    "interval {:g} {}, magnification {}{}",
                                                    axisWord, l.name, t.negative, t.positive, t.reference, t.interval,
                                                    linear ? "mm" : "deg", t.magnification,
                                                    constant && linear ? "; its value at the reference position in the TCP "
                                                                         "offsets and 1220"
                                                                       : "")});
        {
            // Whole detection units per point: the table holds the error to half a unit.
            std::string names;
            for (int di : it->second) names += (names.empty() ? "" : "+") + m.deviations[di].name;
            plan.notCompensated.push_back(
                {fmt::format("{} (rounded to {:g} {})", names, o.unit, linear ? "mm" : "deg"),
                 fmt::format("pitch data are whole detection units (IS-C [G]): up to {:g} {} is left at each point",
                             o.unit / 2 * (linear ? 1000.0 : 3600.0), linear ? "um" : "arcsec")});
        }
        if (constant && !linear) {
            std::string names;
            for (int di : it->second) names += (names.empty() ? "" : "+") + m.deviations[di].name;
            plan.notCompensated.push_back(
                {names + " (constant part)",
                 fmt::format("{} arcsec at the reference position: a zero-position error, which a pitch table cannot hold "
                             "(zero there) nor a TCP parameter (shift the reference position, parameter 1850, by hand [G])",
                             fixed(e0 * 3600.0, 3))});
        }
        plan.tables.push_back(std::move(t));
    }
    return plan;
}

std::vector<Parameter> pitchLines(const MachineModel& m, const std::vector<PitchTable>& tables) {
    std::vector<Parameter> out;
    if (tables.empty()) return out;
    Parameter p[6];
    for (int k = 0; k < 6; ++k) {
        p[k].number = 3620 + k;
        p[k].kind = 'A';
    }
    for (const PitchTable& t : tables) {
        const int n = controllerAxisNumber(m, t.axis);
        p[0].values[n] = std::to_string(t.reference);
        p[1].values[n] = std::to_string(t.negative);
        p[2].values[n] = std::to_string(t.positive);
        p[3].values[n] = std::to_string(t.magnification);
        p[4].values[n] = decimal(t.interval, 4);
        p[5].values[n] = t.rotaryType ? "360.0" : "0.0";
    }
    for (auto& x : p) out.push_back(x);
    for (const PitchTable& t : tables)
        for (int k = t.negative; k <= t.positive; ++k) {
            Parameter d;
            d.number = 10000 + k;
            d.q = 0;
            d.kind = 'P';
            d.values[0] = std::to_string(t.data[k - t.negative]);
            out.push_back(d);
        }
    return out;
}

std::vector<PitchTable> pitchFromFile(const MachineModel& m, const ParameterFile& f) {
    std::vector<PitchTable> out;
    const Parameter* p3620 = f.find(3620);
    std::set<int> used;
    if (p3620) {
        for (const auto& [number, raw] : p3620->values) {
            (void)raw;
            const int a = machineAxisOfNumber(m, number);
            if (a < 0) throw InputError(f.path, p3620->line, fmt::format("parameter 3620: machine '{}' has no axis A{}", m.name, number));
            const auto whole = [&](int param, double lo, double hi) {
                const double v = required(f, param, number);
                if (v != std::floor(v) || v < lo || v > hi)
                    throw InputError(f.path, f.find(param)->line,
                                     fmt::format("parameter {} of axis A{}: {} is not a whole number {}..{}", param, number, v, lo, hi));
                return static_cast<int>(v);
            };
            PitchTable t;
            t.axis = a;
            t.reference = whole(3620, 0, 9999);
            t.negative = whole(3621, 0, 9999);
            t.positive = whole(3622, 0, 9999);
            t.magnification = whole(3623, 1, 100);
            t.interval = required(f, 3624, number);
            const double rev = value(f, 3625, number, 0.0);
            const int line = p3620->line;
            if (!(t.interval > 0)) throw InputError(f.path, f.find(3624)->line, fmt::format("parameter 3624 of axis A{} must be positive", number));
            if (!(t.negative - 1 <= t.reference && t.reference <= t.positive && t.negative <= t.positive))
                throw InputError(f.path, line, fmt::format("axis A{}: points must satisfy 3621 - 1 <= 3620 <= 3622 and 3621 <= 3622 "
                                                           "(got 3620 = {}, 3621 = {}, 3622 = {})",
                                                           number, t.reference, t.negative, t.positive));
            if (rev != 0.0 && rev != 360.0)
                throw InputError(f.path, f.find(3625)->line, fmt::format("parameter 3625 of axis A{}: only 0 or 360 is modelled", number));
            t.rotaryType = rev == 360.0;
            if (t.rotaryType) {
                const Link& l = m.axisLink(a);
                if (l.kind != AxisKind::Rotary || !l.modulo)
                    throw InputError(f.path, f.find(3625)->line, fmt::format("parameter 3625: axis A{} ({}) is not a modulo rotary axis", number, l.name));
                if (t.reference != t.negative || std::abs((t.positive - t.negative) * t.interval - 360.0) > 1e-6)
                    throw InputError(f.path, line, fmt::format("axis A{}: a rotary-axis table starts at the reference point and spans 360 deg", number));
            }
            long sum = 0;
            int lastLine = line;
            for (int k = t.negative; k <= t.positive; ++k) {
                if (!used.insert(k).second) throw InputError(f.path, line, fmt::format("compensation point {} belongs to two axes", k));
                const double v = required(f, 10000 + k, 0, 0);
                const Parameter* dp = f.find(10000 + k, 0);
                lastLine = dp->line;
                if (v != std::floor(v)) throw InputError(f.path, dp->line, fmt::format("pitch data of point {} must be a whole number", k));
                t.data.push_back(static_cast<long>(v));
                if (k > t.negative) sum += static_cast<long>(v);
            }
            if (t.rotaryType && sum != 0)
                throw InputError(f.path, lastLine, fmt::format("axis A{}: rotary-axis pitch data sum to {} over one revolution, not 0", number, sum));
            if (t.rotaryType && t.data.front() != t.data.back())
                throw InputError(f.path, f.find(10000 + t.reference, 0)->line,
                                 fmt::format("axis A{}: the value at the reference point {} ({}) must equal the value at the last point {} ({})",
                                             number, t.reference, t.data.front(), t.positive, t.data.back()));
            out.push_back(std::move(t));
        }
    }
    for (const Parameter& p : f.parameters)
        if (p.q == 0 && !used.count(p.number - 10000))
            throw InputError(f.path, p.line, fmt::format("pitch data point {} lies outside every axis' points (3621..3622)", p.number - 10000));
    return out;
}

}  // namespace cnccomp::controllers::fanuc
