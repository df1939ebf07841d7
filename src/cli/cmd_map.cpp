// cnccomp map: volumetric error map of a machine with a deviation set, as CSV and an SVG picture of one plane.
#include <chrono>
#include <ostream>

#include <fmt/format.h>

#include "cli/command.hpp"
#include "cnccomp/error.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "cnccomp/io/map_csv.hpp"
#include "cnccomp/io/svg_map.hpp"
#include "cnccomp/io/text_util.hpp"
#include "cnccomp/volumetric_map.hpp"

namespace cnccomp::cli {
using namespace cnccomp::io;
namespace {

struct Options {
    std::string machine, deviations, grid, out, svg, plane, orientation;
    double toolLength = 0.0;
    int threads = 0;
};

std::optional<Vec3> parseOrientation(const std::string& text) {
    if (text.empty()) return std::nullopt;
    std::string s = text;
    for (char& c : s)
        if (c == ',') c = ' ';
    Vec3 v;
    int n = 0;
    size_t pos = 0;
    while (pos < s.size()) {
        while (pos < s.size() && s[pos] == ' ') ++pos;
        if (pos >= s.size()) break;
        size_t end = s.find(' ', pos);
        if (end == std::string::npos) end = s.size();
        const auto x = parseNumber(s.substr(pos, end - pos));
        if (!x || !std::isfinite(*x) || n >= 3) throw InputError("--orientation", 0, fmt::format("'{}': expected three numbers I J K", text));
        v[n++] = *x;
        pos = end;
    }
    if (n != 3 || v.norm() < 1e-12) throw InputError("--orientation", 0, fmt::format("'{}': expected a non-zero vector I J K", text));
    return v.normalized();
}

void run(const Options& o) {
    const MachineModel m = readMachineXml(o.machine);
    const DeviationSet d = readDeviationCsv(o.deviations, m);
    MapRequest req{m, d, parseGrid(o.grid), o.toolLength, parseOrientation(o.orientation), o.threads};
    MapPlane plane;
    if (!o.svg.empty()) {
        if (!o.plane.empty()) {
            plane = parseMapPlane(o.plane);
        } else {
            std::vector<std::string> ranges;
            for (const GridAxis& a : req.grid.axes)
                if (a.count > 1) ranges.push_back(a.name);
            if (ranges.size() < 2) throw InputError("--svg", 0, "the grid needs two ranges for a picture (or give --plane)");
            plane.u = ranges[0];
            plane.v = ranges[1];
        }
    }
    refuseToOverwrite(o.out, {o.machine, o.deviations});
    if (!o.svg.empty()) refuseToOverwrite(o.svg, {o.machine, o.deviations, o.out});
    // The map is streamed to the file (memory flat in the grid size); the picture's plane is kept on the way.
    const auto t0 = std::chrono::steady_clock::now();
    VolumetricMap map = describeMap(req);
    std::vector<long> planeIndices;
    if (!o.svg.empty()) planeIndices = planePointIndices(map, plane);
    std::vector<MapPoint> planePoints;
    MapCsvInfo info{m.name, o.deviations, {}};
    // The map is direction-free: the reversal values (backlash) of the set depend on the approach direction.
    std::string reversals;
    for (int a = 0; a < m.axisCount(); ++a)
        if (d.reversalPresent[static_cast<size_t>(a)]) reversals += (reversals.empty() ? "B" : ", B") + m.axisNames[static_cast<size_t>(a)];
    if (!reversals.empty())
        info.reversalNote = fmt::format("reversal values ({}) left out: the map is direction-free, backlash depends on the "
                                        "approach direction", reversals);
    map.stats = streamMapCsv(o.out, req, info, planeIndices, &planePoints);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (!o.svg.empty()) {
        const std::string svgText =
            renderMapSvg(map, planePoints, m, plane, {fmt::format("machine {}, deviations {}", m.name, o.deviations)});
        writeFileAtomically(o.svg, [&](std::ostream& out) { out << svgText; });
    }
    fmt::print("volumetric map of '{}' with {} ({} points, {:.3f} s)\n", m.name, o.deviations, req.grid.size(), seconds);
    if (!info.reversalNote.empty()) fmt::print("  {}\n", info.reversalNote);
    for (const std::string& l : formatMapStatistics(map, m)) fmt::print("  {}\n", l);
    fmt::print("wrote {}{}\n", o.out, o.svg.empty() ? "" : " and " + o.svg);
    if (map.stats.failed > 0)
        fmt::print("warning: {} points could not be reached with the fixed tool orientation (ok=0 in the CSV)\n", map.stats.failed);
}

const RegisterCommand reg([](CLI::App& app) {
    auto o = std::make_shared<Options>();
    auto* c = app.add_subcommand("map", "Volumetric error map (tool-tip and tool-orientation error) over a grid; CSV and SVG");
    c->add_option("--machine", o->machine, "machine description XML")->required()->check(CLI::ExistingFile);
    c->add_option("--deviations", o->deviations, "deviation set CSV")->required()->check(CLI::ExistingFile);
    c->add_option("--grid", o->grid,
                  "grid, e.g. \"X=-200:200:10 Y=-100:100:10 Z=0 B=-90:90:45 C=0\" (from:to:step or one value; "
                  "mm for linear axes, deg for rotary; axes not named stay at 0)")
        ->required();
    c->add_option("--tool-length", o->toolLength, "tool length in mm along the tool direction (default 0)");
    c->add_option("--orientation", o->orientation,
                  "fixed tool axis \"I J K\" (spindle to tip, workpiece frame) instead of rotary angles; the grid "
                  "then gives the tip position X Y Z in the workpiece frame and the nominal inverse kinematics the angles");
    c->add_option("--out", o->out, "map CSV to write")->required();
    c->add_option("--svg", o->svg, "SVG picture of one plane of the grid");
    c->add_option("--plane", o->plane, "plane of the picture, e.g. XY@Z=0 or XZ@Y=0,B=30 (default: the first two ranges)");
    c->add_option("--threads", o->threads, "worker threads (default: all cores)");
    c->callback([o] { run(*o); });
});

}  // namespace
}  // namespace cnccomp::cli
