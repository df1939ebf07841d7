#include "cnccomp/io/map_csv.hpp"

#include <array>
#include <cstdio>
#include <functional>
#include <iterator>
#include <memory>
#include <ostream>
#include <span>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/csv.hpp"
#include "cnccomp/io/number_format.hpp"
#include "cnccomp/io/text_util.hpp"

namespace cnccomp::io {
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

/// The '#' header lines and the column line.
std::string mapHeader(const VolumetricMap& map, const MachineModel& m, const MapCsvInfo& info) {
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
    return out;
}

/// Formats map rows: every axis command (mm, deg) with 6 decimals, the tip (mm) with 6, the errors (µm, arcsec) with
/// 5, ok; the text printf's "%.6f" / "%.5f" would write (NumberStyle::exact), several times faster.
class RowWriter {
public:
    explicit RowWriter(const MachineModel& m) : axes_(m.axisCount()) {
        for (int a = 0; a < axes_; ++a) scale_[a] = m.axisLink(a).kind == AxisKind::Rotary ? 1.0 / kDeg : 1.0;
        six_.decimals = 6;
        six_.exact = true;
        five_.decimals = 5;
        five_.exact = true;
    }
    /// The longest row write() can produce.
    size_t rowMax() const { return (static_cast<size_t>(axes_) + 12) * (kMaxNumberChars + 1) + 2; }
    /// Writes the row of `p` at `out` (rowMax() bytes at least) and returns its length.
    size_t write(const MapPoint& p, char* out) const {
        char* c = out;
        const auto put = [&](double v, const NumberStyle& st) {
            c += formatNumber(v, st, c);
            *c++ = ',';
        };
        for (int a = 0; a < axes_; ++a) put(p.q[a] * scale_[a], six_);
        put(p.tip.x(), six_);
        put(p.tip.y(), six_);
        put(p.tip.z(), six_);
        put(p.error.x() / kUm, five_);
        put(p.error.y() / kUm, five_);
        put(p.error.z() / kUm, five_);
        put(p.error.norm() / kUm, five_);
        put(p.rotation.x() / kArcsec, five_);
        put(p.rotation.y() / kArcsec, five_);
        put(p.rotation.z() / kArcsec, five_);
        put(p.tilt / kArcsec, five_);
        *c++ = p.ok ? '1' : '0';
        *c++ = '\n';
        return static_cast<size_t>(c - out);
    }

private:
    int axes_;
    std::array<double, kMaxAxes> scale_{};
    NumberStyle six_, five_;
};

/// Writes the map through `sink` in chunks (a million-point map never sits in memory twice).
template <class Sink>
void writeMap(const VolumetricMap& map, const MachineModel& m, const MapCsvInfo& info, Sink&& sink) {
    std::string out = mapHeader(map, m, info);
    const RowWriter rows(m);
    std::vector<char> row(rows.rowMax());
    for (const MapPoint& p : map.points) {
        out.append(row.data(), rows.write(p, row.data()));
        if (out.size() > (1u << 20)) {
            sink(out);
            out.clear();
        }
    }
    sink(out);
}

/// streamMapCsv's sink: rows formatted on the workers (one text buffer per slot), written in order, the points the
/// caller asked for copied out.
class CsvSink : public MapSink {
public:
    using Write = std::function<void(const char*, size_t)>;
    CsvSink(const MachineModel& m, Write out, std::span<const long> keep, std::vector<MapPoint>* kept)
        : rows_(m), out_(std::move(out)), keep_(keep), kept_(kept) {}
    void begin(int slots, long blockPoints) override {
        text_.resize(static_cast<size_t>(slots));
        for (Text& t : text_) t.data.reset(new char[static_cast<size_t>(blockPoints) * rows_.rowMax()]);
    }
    void evaluated(int slot, long, std::span<const MapPoint> points) override {
        Text& t = text_[static_cast<size_t>(slot)];
        t.size = 0;
        for (const MapPoint& p : points) t.size += rows_.write(p, t.data.get() + t.size);
    }
    void inOrder(int slot, long first, std::span<const MapPoint> points) override {
        const Text& t = text_[static_cast<size_t>(slot)];
        out_(t.data.get(), t.size);
        const long last = first + static_cast<long>(points.size());
        while (next_ < keep_.size() && keep_[next_] < last) {
            if (keep_[next_] >= first && kept_) kept_->push_back(points[static_cast<size_t>(keep_[next_] - first)]);
            ++next_;
        }
    }

private:
    struct Text {
        std::unique_ptr<char[]> data;  ///< blockPoints rows at most
        size_t size = 0;
    };
    RowWriter rows_;
    Write out_;
    std::span<const long> keep_;
    std::vector<MapPoint>* kept_;
    size_t next_ = 0;
    std::vector<Text> text_;
};

}  // namespace

void appendMapRows(std::span<const MapPoint> points, const MachineModel& m, std::string& out) {
    const RowWriter rows(m);
    std::vector<char> row(rows.rowMax());
    for (const MapPoint& p : points) out.append(row.data(), rows.write(p, row.data()));
}

std::string formatMapCsv(const VolumetricMap& map, const MachineModel& m, const MapCsvInfo& info) {
    std::string all;
    writeMap(map, m, info, [&](const std::string& chunk) { all += chunk; });
    return all;
}

void writeMapCsv(const std::string& path, const VolumetricMap& map, const MachineModel& m, const MapCsvInfo& info) {
    writeFileAtomically(path, [&](std::ostream& o) { writeMap(map, m, info, [&](const std::string& chunk) { o << chunk; }); });
}

MapStatistics streamMapCsv(const std::string& path, const MapRequest& request, const MapCsvInfo& info,
                           std::span<const long> keep, std::vector<MapPoint>* kept) {
    for (size_t i = 1; i < keep.size(); ++i)
        if (keep[i] <= keep[i - 1]) throw ModelError("streamMapCsv: the points to keep must be in increasing order");
    VolumetricMap head = describeMap(request);
    MapStatistics stats;
    if (!request.toolOrientation) {
        // Machine axes: a point costs little, so the statistics for the header take a pass of their own and the rows
        // are written straight into the file on the second.
        head.stats = mapStatistics(request);
        writeFileAtomically(path, [&](std::ostream& o) {
            const std::string h = mapHeader(head, request.machine, info);
            o.write(h.data(), static_cast<std::streamsize>(h.size()));
            if (kept) kept->clear();
            CsvSink sink(request.machine, [&](const char* d, size_t n) { o.write(d, static_cast<std::streamsize>(n)); },
                         keep, kept);
            stats = streamMap(request, sink);
        });
        return stats;
    }
    // A fixed orientation: every point solves the inverse kinematics (tens of times a forward pose), so the grid is
    // evaluated once, its rows spilled into an anonymous temporary file and copied after the header.
    const std::unique_ptr<std::FILE, int (*)(std::FILE*)> spill(std::tmpfile(), &std::fclose);
    if (!spill) throw ModelError(fmt::format("{}: cannot create a temporary file for the map rows", path));
    const auto put = [&](const char* d, size_t n) {
        if (std::fwrite(d, 1, n, spill.get()) != n)
            throw ModelError(fmt::format("{}: cannot write the map rows to a temporary file (disk full?)", path));
    };
    if (kept) kept->clear();
    CsvSink sink(request.machine, put, keep, kept);
    head.stats = stats = streamMap(request, sink);
    if (std::fflush(spill.get()) != 0 || std::fseek(spill.get(), 0, SEEK_SET) != 0)
        throw ModelError(fmt::format("{}: cannot read back the map rows from a temporary file", path));
    writeFileAtomically(path, [&](std::ostream& o) {
        const std::string h = mapHeader(head, request.machine, info);
        o.write(h.data(), static_cast<std::streamsize>(h.size()));
        std::vector<char> buf(size_t{1} << 20);
        for (size_t n; (n = std::fread(buf.data(), 1, buf.size(), spill.get())) > 0;)
            o.write(buf.data(), static_cast<std::streamsize>(n));
        if (std::ferror(spill.get()))
            throw ModelError(fmt::format("{}: cannot read back the map rows from a temporary file", path));
    });
    return stats;
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

}  // namespace cnccomp::io
