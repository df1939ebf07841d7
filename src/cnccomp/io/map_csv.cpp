#include "cnccomp/io/map_csv.hpp"

#include <array>
#include <iterator>
#include <ostream>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/csv.hpp"
#include "cnccomp/io/text_util.hpp"

namespace cnccomp {
namespace {

constexpr const char* kErrorColumns[] = {"x_mm", "y_mm", "z_mm", "dx_um", "dy_um", "dz_um", "e_um",
                                         "ea_arcsec", "eb_arcsec", "ec_arcsec", "tilt_arcsec", "ok"};

std::string where(const MapPoint& p, const MachineModel& m) {
    std::string s;
    for (int a = 0; a < m.axisCount(); ++a) {
        const bool rot = m.axisLink(a).kind == AxisKind::Rotary;
        s += fmt::format("{}{}={:.3f}", s.empty() ? "" : " ", m.axisNames[a], p.q[a] / (rot ? kDeg : 1.0));
    }
    return s;
}

}  // namespace

std::vector<std::string> formatMapStatistics(const VolumetricMap& map, const MachineModel& m) {
    const MapStatistics& s = map.stats;
    std::vector<std::string> out;
    out.push_back(fmt::format("points: {} evaluated, {} failed", s.points, s.failed));
    out.push_back(fmt::format("{:<10} {:>12} {:>12}", "component", "max |.|", "rms"));
    const auto row = [&](const char* n, const ComponentStats& c, double scale, const char* unit) {
        out.push_back(fmt::format("{:<10} {:12.4f} {:12.4f}  {}", n, c.maxAbs * scale, c.rms * scale, unit));
    };
    row("dx", s.dx, 1 / kUm, "um");
    row("dy", s.dy, 1 / kUm, "um");
    row("dz", s.dz, 1 / kUm, "um");
    row("|e|", s.norm, 1 / kUm, "um");
    row("tilt", s.tilt, 1 / kArcsec, "arcsec");
    if (s.worstIndex >= 0) {
        const MapPoint& w = s.worst;
        out.push_back(fmt::format("worst |e| {:.4f} um = ({:.4f}, {:.4f}, {:.4f}) um at {} (tip {:.3f} {:.3f} {:.3f} mm)",
                                  w.error.norm() / kUm, w.error.x() / kUm, w.error.y() / kUm, w.error.z() / kUm,
                                  where(w, m), w.tip.x(), w.tip.y(), w.tip.z()));
    }
    if (s.worstTiltIndex >= 0)
        out.push_back(fmt::format("worst tilt {:.4f} arcsec at {}", s.worstTilt.tilt / kArcsec, where(s.worstTilt, m)));
    return out;
}

namespace {

/// Writes the map through `sink` in chunks (a million-point map never sits in memory twice).
template <class Sink>
void writeMap(const VolumetricMap& map, const MachineModel& m, const MapCsvInfo& info, Sink&& sink) {
    std::string out;
    out += "# cnccomp volumetric error map (errors = actual - nominal, in the workpiece frame)\n";
    out += fmt::format("# machine: {}\n", info.machine.empty() ? m.name : info.machine);
    out += fmt::format("# deviation set: {}\n", info.deviationSource.empty() ? "-" : info.deviationSource);
    if (!info.reversalNote.empty()) out += "# " + info.reversalNote + "\n";
    std::string grid;
    for (const GridAxis& g : map.grid.axes)
        grid += fmt::format("{}{}={}", grid.empty() ? "" : " ", g.name,
                            g.count == 1 ? fmt::format("{:g}", g.from) : fmt::format("{:g}:{:g}:{:g}", g.from, g.to, g.step));
    out += fmt::format("# grid: {}\n", grid);
    out += fmt::format("# tool length: {:g} mm\n", map.toolLength);
    if (map.toolOrientation)
        out += fmt::format("# tool orientation (workpiece frame, spindle to tip): {:.9g} {:.9g} {:.9g}; grid X Y Z = tip\n",
                           map.toolOrientation->x(), map.toolOrientation->y(), map.toolOrientation->z());
    else
        out += "# grid names machine axes; axes not named are held at 0\n";
    for (const std::string& l : formatMapStatistics(map, m)) out += "# " + l + "\n";
    for (int a = 0; a < m.axisCount(); ++a) out += axisColumn(m, a) + ",";
    for (size_t i = 0; i < std::size(kErrorColumns); ++i) out += std::string(kErrorColumns[i]) + (i + 1 < std::size(kErrorColumns) ? "," : "\n");
    std::array<double, kMaxAxes> scale{};
    for (int a = 0; a < m.axisCount(); ++a) scale[a] = m.axisLink(a).kind == AxisKind::Rotary ? 1.0 / kDeg : 1.0;
    for (const MapPoint& p : map.points) {
        for (int a = 0; a < m.axisCount(); ++a) fmt::format_to(std::back_inserter(out), "{:.6f},", p.q[a] * scale[a]);
        fmt::format_to(std::back_inserter(out), "{:.6f},{:.6f},{:.6f},{:.5f},{:.5f},{:.5f},{:.5f},{:.5f},{:.5f},{:.5f},{:.5f},{}\n", p.tip.x(),
                       p.tip.y(), p.tip.z(), p.error.x() / kUm, p.error.y() / kUm, p.error.z() / kUm, p.error.norm() / kUm,
                       p.rotation.x() / kArcsec, p.rotation.y() / kArcsec, p.rotation.z() / kArcsec, p.tilt / kArcsec, p.ok ? 1 : 0);
        if (out.size() > (1u << 20)) {
            sink(out);
            out.clear();
        }
    }
    sink(out);
}

}  // namespace

std::string formatMapCsv(const VolumetricMap& map, const MachineModel& m, const MapCsvInfo& info) {
    std::string all;
    writeMap(map, m, info, [&](const std::string& chunk) { all += chunk; });
    return all;
}

void writeMapCsv(const std::string& path, const VolumetricMap& map, const MachineModel& m, const MapCsvInfo& info) {
    writeFileAtomically(path, [&](std::ostream& o) { writeMap(map, m, info, [&](const std::string& chunk) { o << chunk; }); });
}

MapCsvTable readMapCsv(const std::string& path) {
    const CsvTable t = readCsv(path);
    MapCsvTable out;
    std::vector<int> axisCols;
    std::vector<double> axisScale;
    for (size_t c = 0; c < t.header.cells.size(); ++c) {
        const std::string& h = t.header.cells[c];
        const bool deg = h.size() > 4 && h.ends_with("_deg");
        const bool mm = h.size() > 3 && h.ends_with("_mm") && h != "x_mm" && h != "y_mm" && h != "z_mm";
        if (!deg && !mm) continue;
        out.axisNames.push_back(h.substr(0, h.size() - (deg ? 4 : 3)));
        axisCols.push_back(static_cast<int>(c));
        axisScale.push_back(deg ? kDeg : 1.0);
    }
    if (out.axisNames.empty() || static_cast<int>(out.axisNames.size()) > kMaxAxes)
        throw InputError(path, t.header.line, fmt::format("expected 1..{} axis columns NAME_mm / NAME_deg", kMaxAxes));
    int cols[std::size(kErrorColumns)];
    for (size_t i = 0; i < std::size(kErrorColumns); ++i) cols[i] = t.requireColumn(kErrorColumns[i]);
    for (const CsvRow& row : t.rows) {
        MapPoint p;
        for (size_t a = 0; a < axisCols.size(); ++a) p.q[a] = t.requireNumber(row, axisCols[a]) * axisScale[a];
        double v[std::size(kErrorColumns)];
        for (size_t i = 0; i < std::size(kErrorColumns); ++i) v[i] = t.requireNumber(row, cols[i]);
        p.tip = Vec3(v[0], v[1], v[2]);
        p.error = Vec3(v[3], v[4], v[5]) * kUm;
        p.rotation = Vec3(v[7], v[8], v[9]) * kArcsec;
        p.tilt = v[10] * kArcsec;
        if (v[11] != 0 && v[11] != 1) throw InputError(path, row.line, "column 'ok' must be 0 or 1");
        p.ok = v[11] == 1;
        out.points.push_back(p);
    }
    return out;
}

}  // namespace cnccomp
