#include "controllers/generic/grid_map.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <set>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/inverse_kinematics.hpp"
#include "cnccomp/io/csv.hpp"
#include "cnccomp/io/text_util.hpp"
#include "controllers/common/controller_model.hpp"
#include "controllers/common/files.hpp"
#include "controllers/generic/json_text.hpp"
#include "cnccomp/io/markup.hpp"

namespace cnccomp::controllers::generic {
using namespace cnccomp::controllers::common;
using namespace cnccomp::io;
namespace {

// Machine-frame errors (version 2; version 1 had workpiece-frame columns dx_um ... dkz_urad, which the reader refuses).
constexpr const char* kValueColumns[] = {"dx_machine_um",     "dy_machine_um",     "dz_machine_um",
                                         "dkx_machine_urad", "dky_machine_urad", "dkz_machine_urad"};

double unitOf(bool rotary) { return rotary ? kDeg : 1.0; }

}  // namespace

void GridMap::at(const AxisVector& q, Vec3& tipError, Vec3& axisError) const {
    const int n = static_cast<int>(axes.size());
    std::array<long, kMaxAxes> base{}, stride{};
    std::array<double, kMaxAxes> frac{};
    std::array<int, kMaxAxes> varying{};
    int nv = 0;
    long s = 1;
    for (int a = n - 1; a >= 0; --a) {
        stride[a] = s;
        s *= static_cast<long>(axes[a].nodes.size());
    }
    for (int a = 0; a < n; ++a) {
        const std::vector<double>& x = axes[a].nodes;
        double v = q[axes[a].axis];
        if (axes[a].wraps) {
            v = std::fmod(v - x.front(), 2 * kPi);
            if (v < 0) v += 2 * kPi;
            v += x.front();
        }
        if (x.size() == 1 || v <= x.front()) {
            base[a] = 0;
            frac[a] = 0;
        } else if (v >= x.back()) {
            base[a] = static_cast<long>(x.size()) - 2;
            frac[a] = 1;
        } else {
            const long i = static_cast<long>(std::upper_bound(x.begin(), x.end(), v) - x.begin()) - 1;
            base[a] = i;
            frac[a] = (v - x[i]) / (x[i + 1] - x[i]);
        }
        if (x.size() > 1) varying[nv++] = a;
    }
    tipError.setZero();
    axisError.setZero();
    for (long corner = 0; corner < (1L << nv); ++corner) {
        double w = 1;
        long index = 0;
        for (int a = 0; a < n; ++a) index += base[a] * stride[a];
        for (int k = 0; k < nv; ++k) {
            const int a = varying[k];
            const bool hi = (corner >> k) & 1;
            w *= hi ? frac[a] : 1 - frac[a];
            index += hi ? stride[a] : 0;
        }
        if (w == 0) continue;
        tipError += w * tip[index];
        axisError += w * toolAxis[index];
    }
}

namespace {

/// Travel of an axis on the map: rotary axes clamped to ±180°.
std::pair<double, double> mapTravel(const Link& l) {
    double lo = l.min, hi = l.max;
    if (l.kind == AxisKind::Rotary) {
        lo = std::max(lo, -kPi);
        hi = std::min(hi, kPi);
    }
    if (!std::isfinite(lo) || !std::isfinite(hi) || !(hi > lo))
        throw ModelError(fmt::format("axis {} has no finite travel: the grid map needs one", l.name));
    return {lo, hi};
}

/// Ends of the travel and the nodes of the axis' table-type component errors inside it: the tip error has a kink
/// there, which multilinear interpolation only reproduces with a node on it.
std::vector<double> baseNodes(const MachineModel& m, const DeviationSet& d, int a) {
    const Link& l = m.axisLink(a);
    const auto [lo, hi] = mapTravel(l);
    std::set<double> s = {lo, hi};
    for (size_t k = 0; k < m.deviations.size(); ++k) {
        const DeviationDef& def = m.deviations[k];
        if (!d.present[k] || def.kind != DeviationKind::Component || m.chain(def.side).links[def.link].axisIndex != a) continue;
        if (def.basis.type != ComponentBasis::Type::Table) continue;
        for (double n : def.basis.nodes) {
            double u = n;
            if (l.modulo) u = std::remainder(u, 2 * kPi);  // into [-π, π]
            if (u > lo + 1e-12 && u < hi - 1e-12) s.insert(u);
        }
    }
    return {s.begin(), s.end()};
}

/// Values of the other axes at which an axis' nodes are tested: linear axes at their ends (the tip error of location
/// errors is affine in a linear axis), the middle too when it carries component errors, rotary axes every 30°.
std::vector<std::vector<double>> probeValues(const MachineModel& m, const std::vector<std::vector<double>>& base) {
    std::vector<std::vector<double>> out(static_cast<size_t>(m.axisCount()));
    for (int a = 0; a < m.axisCount(); ++a) {
        const Link& l = m.axisLink(a);
        const auto [lo, hi] = mapTravel(l);
        const int count = l.kind == AxisKind::Rotary ? static_cast<int>(std::ceil((hi - lo) / (30 * kDeg) - 1e-9)) + 1
                                                     : (base[static_cast<size_t>(a)].size() > 2 ? 5 : 2);
        for (int i = 0; i < count; ++i) out[static_cast<size_t>(a)].push_back(lo + (hi - lo) * i / (count - 1));
    }
    return out;
}

}  // namespace

void machineFrameError(const Kinematics& nominal, const Kinematics& actual, const AxisVector& q, Vec3& tipError,
                       Vec3& axisError) {
    const Vec3 tip0 = nominal.toolPoint(0.0);
    const ToolPose n = toolPose(nominal, q, tip0), e = toolPose(actual, q, tip0);
    const Mat3 bRw = nominal.baseToWorkpiece(q).linear();
    tipError = bRw * (e.tip - n.tip);
    axisError = bRw * (e.axis - n.axis);
}

GridMap buildGridMap(const MachineModel& m, const DeviationSet& d, const GridMapOptions& o) {
    if (!(o.tolerance > 0) || !(o.toolLength >= 0) || o.maxNodes < 2)
        throw ModelError("grid map: tolerance, tool length and node budget must be positive");
    const Kinematics nominal(m), actual(m, d);
    const int n = m.axisCount();
    // The map's value at commands q: the tip error at tool length 0 and at the reference length (both interpolated).
    const auto value = [&](const AxisVector& q) {
        Vec3 tip, axis;
        machineFrameError(nominal, actual, q, tip, axis);
        Vec6 v;
        v.head<3>() = tip;
        v.tail<3>() = tip + o.toolLength * axis;
        return v;
    };
    std::vector<std::vector<double>> base(static_cast<size_t>(n));
    for (int a = 0; a < n; ++a) base[static_cast<size_t>(a)] = baseNodes(m, d, a);
    const auto probes = probeValues(m, base);
    // Per axis: the other axes at their probe values (all combinations, at most ~250 of them, evenly strided).
    std::vector<std::vector<AxisVector>> others(static_cast<size_t>(n));
    for (int a = 0; a < n; ++a) {
        long combos = 1;
        for (int o2 = 0; o2 < n; ++o2)
            if (o2 != a) combos *= static_cast<long>(probes[static_cast<size_t>(o2)].size());
        const long stride = std::max(1L, combos / 250);
        for (long c = 0; c < combos; c += stride) {
            AxisVector q = AxisVector::Zero(n);
            long r = c;
            for (int o2 = n - 1; o2 >= 0; --o2) {
                if (o2 == a) continue;
                const auto& v = probes[static_cast<size_t>(o2)];
                q[o2] = v[static_cast<size_t>(r % static_cast<long>(v.size()))];
                r /= static_cast<long>(v.size());
            }
            others[static_cast<size_t>(a)].push_back(q);
        }
    }
    // Each base interval split evenly into as many parts as keep the midpoint deviation of the linear interpolation
    // (h²/8 · curvature) within the tolerance for every probe: parts and the deviation they leave, from a first guess.
    struct Split {
        int k = 1;
        double worst = 0;
    };
    const auto split = [&](int a, double u, double v, double tolerance, int k) {
        for (;;) {
            double worst = 0;
            for (AxisVector q : others[static_cast<size_t>(a)]) {
                const auto at = [&](double x) {
                    q[a] = x;
                    return value(q);
                };
                Vec6 left = at(u);
                for (int j = 1; j <= k; ++j) {
                    const double x0 = u + (v - u) * (j - 1) / k, x1 = j == k ? v : u + (v - u) * j / k;
                    const Vec6 right = at(x1), mid = at(0.5 * (x0 + x1));
                    const Vec6 dev = mid - 0.5 * (left + right);
                    worst = std::max({worst, dev.head<3>().norm(), dev.tail<3>().norm()});
                    left = right;
                }
            }
            if (worst <= tolerance) return Split{k, worst};
            if (k >= 100000)
                throw ModelError(fmt::format("grid map: axis {} needs more than {} nodes per interval for {} um",
                                             m.axisNames[a], k, tolerance / kUm));
            k = std::max(k + 1, static_cast<int>(std::ceil(k * std::sqrt(worst / tolerance) * 1.05)));
        }
    };
    std::vector<std::vector<Split>> splits(static_cast<size_t>(n));
    for (int a = 0; a < n; ++a) {
        const auto& b = base[static_cast<size_t>(a)];
        for (size_t i = 0; i + 1 < b.size(); ++i) splits[static_cast<size_t>(a)].push_back(split(a, b[i], b[i + 1], o.tolerance, 1));
    }
    const auto nodeCount = [&] {
        long total = 1;
        for (const auto& axis : splits) {
            long count = 1;
            for (const Split& p : axis) count += p.k;
            total *= count;
        }
        return total;
    };
    GridMap g;
    g.tolerance = o.tolerance;
    if (nodeCount() > o.maxNodes) {
        long least = 1;
        for (const auto& b : base) least *= static_cast<long>(b.size());
        if (least > o.maxNodes)
            throw ModelError(fmt::format("the grid map needs at least {} nodes (the travel ends and the component tables' "
                                         "nodes); the limit is {}",
                                         least, o.maxNodes));
        // The tolerance doubles until the grid fits the node budget (many component errors on many axes): the parts
        // predicted from the deviation's 1/k² law, then checked (a check that needs more parts doubles again).
        const auto exact = splits;
        for (;;) {
            g.tolerance *= 2;
            for (size_t a = 0; a < splits.size(); ++a)
                for (size_t i = 0; i < splits[a].size(); ++i) {
                    const Split& e = exact[a][i];
                    splits[a][i].k = std::max(1, static_cast<int>(std::ceil(e.k * std::sqrt(e.worst / g.tolerance) - 1e-9)));
                }
            if (nodeCount() > o.maxNodes) continue;
            for (int a = 0; a < n; ++a) {
                const auto& b = base[static_cast<size_t>(a)];
                for (size_t i = 0; i + 1 < b.size(); ++i) {
                    Split& p = splits[static_cast<size_t>(a)][i];
                    p = split(a, b[i], b[i + 1], g.tolerance, p.k);
                }
            }
            if (nodeCount() <= o.maxNodes) break;
        }
    }
    for (int a = 0; a < n; ++a) {
        const Link& l = m.axisLink(a);
        GridMapAxis ax;
        ax.axis = a;
        ax.rotary = l.kind == AxisKind::Rotary;
        const auto& b = base[static_cast<size_t>(a)];
        ax.wraps = l.modulo && std::abs(b.back() - b.front() - 2 * kPi) < 1e-12;
        ax.nodes.push_back(b.front());
        for (size_t i = 0; i + 1 < b.size(); ++i) {
            const int k = splits[static_cast<size_t>(a)][i].k;
            for (int j = 1; j <= k; ++j) ax.nodes.push_back(j == k ? b[i + 1] : b[i] + (b[i + 1] - b[i]) * j / k);
        }
        g.axes.push_back(std::move(ax));
    }
    long total = 1;
    for (const GridMapAxis& ax : g.axes) total *= static_cast<long>(ax.nodes.size());
    g.tip.resize(static_cast<size_t>(total));
    g.toolAxis.resize(static_cast<size_t>(total));
    AxisVector q(n);
    for (long i = 0; i < total; ++i) {
        long r = i;
        for (int a = n - 1; a >= 0; --a) {
            const auto& x = g.axes[a].nodes;
            q[a] = x[static_cast<size_t>(r % static_cast<long>(x.size()))];
            r /= static_cast<long>(x.size());
        }
        machineFrameError(nominal, actual, q, g.tip[i], g.toolAxis[i]);
    }
    return g;
}

std::string formatGridMapCsv(const GridMap& g, const MachineModel& m, const std::string& header) {
    std::string s = header;
    s += "# tool-tip error at tool length 0 (dx dy dz, um) and tool-axis unit-vector error (dkx dky dkz, urad) of the tool\n"
         "# relative to the workpiece, along the machine's X Y Z (bed frame); error at tool length L = (dx dy dz) + L * (dkx dky dkz);\n"
         "# rows: last axis fastest; interpolate multilinearly\n";
    for (int a = 0; a < m.axisCount(); ++a) s += axisColumn(m, a) + ",";
    for (size_t i = 0; i < std::size(kValueColumns); ++i) s += std::string(kValueColumns[i]) + (i + 1 < std::size(kValueColumns) ? "," : "\n");
    std::vector<size_t> idx(g.axes.size(), 0);
    for (size_t i = 0; i < g.tip.size(); ++i) {
        for (size_t a = 0; a < g.axes.size(); ++a)  // machine coordinates: command - machine-zero
            s += fixed((g.axes[a].nodes[idx[a]] - m.axisLink(g.axes[a].axis).machineZero) / unitOf(g.axes[a].rotary), 6) + ",";
        const Vec3 &t = g.tip[i], &k = g.toolAxis[i];
        s += fmt::format("{},{},{},{},{},{}\n", fixed(t.x() / kUm, 6), fixed(t.y() / kUm, 6), fixed(t.z() / kUm, 6),
                         fixed(k.x() * 1e6, 6), fixed(k.y() * 1e6, 6), fixed(k.z() * 1e6, 6));
        for (int a = static_cast<int>(g.axes.size()) - 1; a >= 0; --a) {
            if (++idx[a] < g.axes[a].nodes.size()) break;
            idx[a] = 0;
        }
    }
    return s;
}

std::string formatGridMapJson(const GridMap& g, const MachineModel& m, const std::vector<std::string>& header) {
    std::string s = "{\n  \"format\": \"cnccomp-grid-map\",\n  \"version\": 2,\n  \"header\": [\n";
    for (size_t i = 0; i < header.size(); ++i) s += "    " + jsonString(header[i]) + (i + 1 < header.size() ? ",\n" : "\n");
    s += fmt::format("  ],\n  \"machine\": {},\n  \"toolLength_mm\": 0,\n", jsonString(m.name));
    s += "  \"frame\": \"machine (bed): errors of the tool relative to the workpiece along the machine's X Y Z\",\n";
    s += "  \"order\": \"row-major over grid, last axis fastest; error at tool length L = tip + L * toolAxis\",\n  \"grid\": [\n";
    for (size_t a = 0; a < g.axes.size(); ++a) {
        std::vector<double> nodes;
        const double zero = m.axisLink(g.axes[a].axis).machineZero;
        for (double v : g.axes[a].nodes) nodes.push_back(std::stod(fixed((v - zero) / unitOf(g.axes[a].rotary), 6)));
        s += fmt::format("    {{\"axis\": {}, \"unit\": \"{}\", \"wraps\": {}, \"nodes\": {}}}{}\n", jsonString(m.axisNames[g.axes[a].axis]),
                         g.axes[a].rotary ? "deg" : "mm", g.axes[a].wraps ? "true" : "false", jsonNumbers(nodes),
                         a + 1 < g.axes.size() ? "," : "");
    }
    s += "  ],\n";
    const auto column = [&](const char* name, bool tipColumn, int k, bool last) {
        std::vector<double> v;
        for (size_t i = 0; i < g.tip.size(); ++i)
            v.push_back(std::stod(fixed(tipColumn ? g.tip[i][k] / kUm : g.toolAxis[i][k] * 1e6, 6)));
        s += fmt::format("  \"{}\": {}{}\n", name, jsonNumbers(v), last ? "" : ",");
    };
    for (int k = 0; k < 3; ++k) column(kValueColumns[k], true, k, false);
    for (int k = 0; k < 3; ++k) column(kValueColumns[3 + k], false, k, k == 2);
    s += "}\n";
    return s;
}

GridMap parseGridMapCsv(const std::string& text, const std::string& file, const MachineModel& m) {
    std::vector<std::string> header;
    int headerLine = 0;
    std::vector<std::vector<double>> rows;
    std::vector<int> lines;
    CsvReader reader(text, file);  // the one CSV reader (io/csv.hpp): BOM, CRLF, quoting, line numbers
    header = reader.header().cells;
    headerLine = reader.header().line;
    CsvRow row;
    while (reader.next(row)) {
        if (row.cells.size() != header.size())
            throw InputError(file, row.line, fmt::format("{} cells for {} columns", row.cells.size(), header.size()));
        std::vector<double> v;
        for (size_t i = 0; i < row.cells.size(); ++i)
            v.push_back(requireNumber(row.cells[i], file, row.line, "a value of " + header[i]));
        rows.push_back(std::move(v));
        lines.push_back(row.line);
    }
    const int n = m.axisCount();
    if (static_cast<int>(header.size()) != n + 6) throw InputError(file, headerLine, fmt::format("expected {} axis columns and 6 error columns", n));
    for (int a = 0; a < n; ++a)
        if (header[a] != axisColumn(m, a)) throw InputError(file, headerLine, fmt::format("column {} must be {}", a + 1, axisColumn(m, a)));
    for (int k = 0; k < 6; ++k)
        if (header[n + k] != kValueColumns[k]) throw InputError(file, headerLine, fmt::format("column {} must be {}", n + k + 1, kValueColumns[k]));
    if (rows.empty()) throw InputError(file, headerLine, "no data rows");
    GridMap g;
    long total = 1;
    std::vector<std::vector<double>> fileNodes(n);
    for (int a = 0; a < n; ++a) {
        const Link& l = m.axisLink(a);
        GridMapAxis ax;
        ax.axis = a;
        ax.rotary = l.kind == AxisKind::Rotary;
        std::set<double> values;
        for (const auto& r : rows) values.insert(r[a]);
        fileNodes[a].assign(values.begin(), values.end());
        for (double v : values) ax.nodes.push_back(v * unitOf(ax.rotary) + l.machineZero);  // file: machine coordinates
        ax.wraps = l.modulo && ax.nodes.size() > 1 && std::abs(ax.nodes.back() - ax.nodes.front() - 2 * kPi) < 1e-9;
        total *= static_cast<long>(ax.nodes.size());
        g.axes.push_back(std::move(ax));
    }
    if (total != static_cast<long>(rows.size()))
        throw InputError(file, headerLine, fmt::format("{} rows do not form a full grid ({} nodes)", rows.size(), total));
    for (size_t i = 0; i < rows.size(); ++i) {
        long r = static_cast<long>(i);
        for (int a = n - 1; a >= 0; --a) {
            const auto& x = fileNodes[a];
            const double want = x[static_cast<size_t>(r % static_cast<long>(x.size()))];
            r /= static_cast<long>(x.size());
            if (rows[i][a] != want) throw InputError(file, lines[i], "rows are not in grid order (last axis fastest)");
        }
        g.tip.emplace_back(rows[i][n] * kUm, rows[i][n + 1] * kUm, rows[i][n + 2] * kUm);
        g.toolAxis.emplace_back(rows[i][n + 3] * 1e-6, rows[i][n + 4] * 1e-6, rows[i][n + 5] * 1e-6);
    }
    return g;
}

}  // namespace cnccomp::controllers::generic
