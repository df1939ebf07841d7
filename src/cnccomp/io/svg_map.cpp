#include "cnccomp/io/svg_map.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/markup.hpp"
#include "cnccomp/io/text_util.hpp"

namespace cnccomp::io {
namespace {

const char* kSource = "--plane";

/// Viridis, sampled at 9 points and interpolated linearly.
std::string colour(double t) {
    static constexpr std::array<std::array<double, 3>, 9> c{{{68, 1, 84},
                                                              {71, 44, 122},
                                                              {59, 81, 139},
                                                              {44, 113, 142},
                                                              {33, 144, 141},
                                                              {39, 173, 129},
                                                              {92, 200, 99},
                                                              {170, 220, 50},
                                                              {253, 231, 37}}};
    t = std::clamp(std::isfinite(t) ? t : 0.0, 0.0, 1.0) * 8.0;
    const int i = std::min(7, static_cast<int>(t));
    const double f = t - i;
    int rgb[3];
    for (int k = 0; k < 3; ++k) rgb[k] = static_cast<int>(std::lround(c[i][k] + (c[i + 1][k] - c[i][k]) * f));
    return fmt::format("#{:02x}{:02x}{:02x}", rgb[0], rgb[1], rgb[2]);
}

/// Round tick spacing giving about `n` ticks over [lo, hi].
double niceStep(double lo, double hi, int n) {
    const double raw = (hi - lo) / std::max(1, n);
    if (!(raw > 0)) return 1.0;
    const double p = std::pow(10.0, std::floor(std::log10(raw)));
    for (double m : {1.0, 2.0, 2.5, 5.0, 10.0})
        if (m * p >= raw) return m * p;
    return 10 * p;
}

std::string escape(std::string_view s) { return escapeXml(s, "map text"); }

std::string unitOf(const MachineModel& m, const VolumetricMap& map, const std::string& axis) {
    if (map.toolOrientation) return "mm";
    const int a = m.axisIndex(axis);
    return a >= 0 && m.axisLink(a).kind == AxisKind::Rotary ? "deg" : "mm";
}

/// What a plane coordinate is: a machine axis command, or the tool tip in the workpiece frame (orientation mode).
std::string axisLabel(const MachineModel& m, const VolumetricMap& map, const std::string& axis) {
    if (map.toolOrientation) return fmt::format("tool tip {} in the workpiece frame ({})", axis, unitOf(m, map, axis));
    return fmt::format("{} axis position ({})", axis, unitOf(m, map, axis));
}

/// The plane's grid: axis indices and the cut along every other grid axis.
struct PlaneCut {
    int iu = -1, iv = -1;
    std::vector<long> cut;
    std::string text;
};

PlaneCut planeCut(const VolumetricMap& map, const MachineModel* m, const MapPlane& plane) {
    const MapGrid& g = map.grid;
    PlaneCut c;
    c.iu = g.find(plane.u);
    c.iv = g.find(plane.v);
    if (c.iu < 0 || c.iv < 0 || g.axes[c.iu].count < 2 || g.axes[c.iv].count < 2)
        throw InputError(kSource, 0, fmt::format("plane axes {} and {} must both be ranges of the grid", plane.u, plane.v));
    c.cut.assign(g.axes.size(), 0);
    for (size_t i = 0; i < g.axes.size(); ++i) {
        if (static_cast<int>(i) == c.iu || static_cast<int>(i) == c.iv) continue;
        const GridAxis& a = g.axes[i];
        double want = 0.0;
        bool given = false;
        for (const auto& [n, v] : plane.at)
            if (n == a.name) want = v, given = true;
        long best = 0;
        for (long k = 1; k < a.count; ++k)
            if (std::abs(a.value(k) - want) < std::abs(a.value(best) - want)) best = k;
        if (given && std::abs(a.value(best) - want) > 1e-6 * std::max(1.0, std::abs(want)))
            throw InputError(kSource, 0, fmt::format("{}={:g} is not a grid value (nearest {:g})", a.name, want, a.value(best)));
        c.cut[i] = best;
        if (m) c.text += fmt::format("{}{}={:g} {}", c.text.empty() ? "" : ", ", a.name, a.value(best), unitOf(*m, map, a.name));
    }
    for (const auto& [n, v] : plane.at)
        if (g.find(n) < 0 || n == plane.u || n == plane.v)
            throw InputError(kSource, 0, fmt::format("'{}' is not a grid axis across the plane", n));
    return c;
}

long flatIndex(const MapGrid& g, const PlaneCut& c, long ku, long kv) {
    long index = 0;
    for (size_t i = 0; i < g.axes.size(); ++i) {
        const long k = static_cast<int>(i) == c.iu ? ku : static_cast<int>(i) == c.iv ? kv : c.cut[i];
        index = index * g.axes[i].count + k;
    }
    return index;
}

}  // namespace

MapPlane parseMapPlane(std::string_view text) {
    const std::string s(trim(text));
    MapPlane p;
    const size_t at = s.find('@');
    const std::string axes = s.substr(0, at);
    // Two axis names: single letters "XY", or two names separated by '-' or '/' ("X/C1").
    size_t sep = axes.find_first_of("-/");
    if (sep == std::string::npos) {
        if (axes.size() != 2) throw InputError(kSource, 0, fmt::format("'{}': expected two axes like XY@Z=0", s));
        sep = 1;
        p.u = axes.substr(0, 1);
        p.v = axes.substr(1, 1);
    } else {
        p.u = axes.substr(0, sep);
        p.v = axes.substr(sep + 1);
    }
    if (p.u.empty() || p.v.empty() || p.u == p.v)
        throw InputError(kSource, 0, fmt::format("'{}': expected two different axes like XY@Z=0", s));
    if (at == std::string::npos) return p;
    std::string rest = s.substr(at + 1);
    for (char& c : rest)
        if (c == ',') c = ' ';
    size_t pos = 0;
    while (pos < rest.size()) {
        while (pos < rest.size() && rest[pos] == ' ') ++pos;
        if (pos >= rest.size()) break;
        size_t end = rest.find(' ', pos);
        if (end == std::string::npos) end = rest.size();
        const std::string item = rest.substr(pos, end - pos);
        pos = end;
        const size_t eq = item.find('=');
        const auto v = eq == std::string::npos ? std::nullopt : parseNumber(item.substr(eq + 1));
        if (eq == 0 || !v || !std::isfinite(*v)) throw InputError(kSource, 0, fmt::format("'{}': expected NAME=value", item));
        p.at.emplace_back(item.substr(0, eq), *v);
    }
    return p;
}

double planeMaxError(const VolumetricMap& map, const MapPlane& plane) {
    const PlaneCut c = planeCut(map, nullptr, plane);
    double e = 0;
    for (long ku = 0; ku < map.grid.axes[c.iu].count; ++ku)
        for (long kv = 0; kv < map.grid.axes[c.iv].count; ++kv) {
            const MapPoint& p = map.points[flatIndex(map.grid, c, ku, kv)];
            if (p.ok) e = std::max(e, p.error.norm());
        }
    return e;
}

std::vector<long> planePointIndices(const VolumetricMap& map, const MapPlane& plane) {
    const PlaneCut c = planeCut(map, nullptr, plane);
    std::vector<long> out;
    out.reserve(static_cast<size_t>(map.grid.axes[c.iu].count * map.grid.axes[c.iv].count));
    for (long ku = 0; ku < map.grid.axes[c.iu].count; ++ku)
        for (long kv = 0; kv < map.grid.axes[c.iv].count; ++kv) out.push_back(flatIndex(map.grid, c, ku, kv));
    return out;
}

namespace {

/// The picture, its points from `planePoints` (u-major, planePointIndices' order) or, without, from map.points.
std::string render(const VolumetricMap& map, const std::vector<MapPoint>* planePoints, const MachineModel& m,
                   const MapPlane& plane, const SvgInfo& info) {
    const MapGrid& g = map.grid;
    const PlaneCut pc = planeCut(map, &m, plane);
    const int iu = pc.iu, iv = pc.iv;
    const std::string& cutText = pc.text;
    const GridAxis &au = g.axes[iu], &av = g.axes[iv];
    if (planePoints && static_cast<long>(planePoints->size()) != au.count * av.count)
        throw ModelError(fmt::format("map picture: {} points given for a plane of {} x {}", planePoints->size(), au.count,
                                     av.count));
    const auto point = [&](long ku, long kv) -> const MapPoint& {
        return planePoints ? (*planePoints)[static_cast<size_t>(ku * av.count + kv)]
                           : map.points[static_cast<size_t>(flatIndex(g, pc, ku, kv))];
    };
    const std::string id = escape(info.idPrefix);
    // Plane statistics.
    double emax = 0, emin = HUGE_VAL, sum = 0;
    long n = 0;
    for (long ku = 0; ku < au.count; ++ku)
        for (long kv = 0; kv < av.count; ++kv) {
            const MapPoint& p = point(ku, kv);
            if (!p.ok) continue;
            emax = std::max(emax, p.error.norm());
            emin = std::min(emin, p.error.norm());
            sum += p.error.squaredNorm();
            ++n;
        }
    const double rms = n > 0 ? std::sqrt(sum / n) : 0.0;
    // Colour scale from 0 to a round value at or above the plane's maximum (or the shared maximum given).
    if (n == 0) emin = emax = 0;
    if (!(info.scaleMaxUm >= 0) || !std::isfinite(info.scaleMaxUm))
        throw ModelError("map picture: the colour scale maximum must be a finite number >= 0 um");
    const double clo = 0.0;
    double chi = std::max(info.scaleMaxUm > 0 ? info.scaleMaxUm : 0.0, emax / kUm);
    if (!(chi > 1e-6)) chi = 1.0;  // an all-zero plane: a 0..1 µm scale
    const double cstep = niceStep(0.0, chi, 5);
    const double ctop = std::ceil(chi / cstep - 1e-9) * cstep;
    const auto shade = [&](double um) { return colour((um - clo) / (ctop - clo)); };

    // Geometry: cells centred on the nodes; equal scales when both axes are in the same unit.
    const double uLo = au.from - au.step / 2, uHi = au.to + au.step / 2;
    const double vLo = av.from - av.step / 2, vHi = av.to + av.step / 2;
    const double W = 960, H = 780, left = 90, top = 112, maxW = 640, maxH = 560;
    double sx = maxW / (uHi - uLo), sy = maxH / (vHi - vLo);
    if (unitOf(m, map, plane.u) == unitOf(m, map, plane.v)) sx = sy = std::min(sx, sy);
    const double pw = sx * (uHi - uLo), ph = sy * (vHi - vLo);
    const auto X = [&](double u) { return left + (u - uLo) * sx; };
    const auto Y = [&](double v) { return top + ph - (v - vLo) * sy; };

    std::string s;
    s += fmt::format(R"(<svg xmlns="http://www.w3.org/2000/svg" width="{0}" height="{1}" viewBox="0 0 {0} {1}" font-family="Helvetica, Arial, sans-serif">)",
                     W, H);
    s += fmt::format("\n<defs><clipPath id=\"{}-frame\"><rect x=\"{:.2f}\" y=\"{:.2f}\" width=\"{:.2f}\" height=\"{:.2f}\"/></clipPath>",
                     id, left, top, pw, ph);
    s += "<marker id=\"" + id + "-head\" markerUnits=\"userSpaceOnUse\" markerWidth=\"7\" markerHeight=\"6\" refX=\"6\" refY=\"3\" orient=\"auto\">"
         "<path d=\"M0,0 L7,3 L0,6 z\" fill=\"white\" stroke=\"black\" stroke-width=\"0.4\"/></marker>\n"
         "<linearGradient id=\"" + id + "-bar\" x1=\"0\" y1=\"1\" x2=\"0\" y2=\"0\">";
    for (int k = 0; k <= 8; ++k) s += fmt::format("<stop offset=\"{:.3f}\" stop-color=\"{}\"/>", k / 8.0, colour(k / 8.0));
    s += "</linearGradient></defs>\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
    s += fmt::format("<text x=\"{}\" y=\"32\" font-size=\"20\" font-weight=\"bold\">Volumetric tool-tip error |e| on the {}{} plane</text>\n",
                     left, plane.u, plane.v);
    s += fmt::format("<text x=\"{}\" y=\"54\" font-size=\"13\">{}</text>\n", left, escape(info.title));
    s += fmt::format("<text x=\"{}\" y=\"74\" font-size=\"13\">{}tool length {:g} mm{} — plane max {:.2f} µm, rms {:.2f} µm</text>\n",
                     left, cutText.empty() ? "" : escape(cutText) + "; ", map.toolLength,
                     map.toolOrientation ? fmt::format(", tool axis ({:.3g}, {:.3g}, {:.3g})", map.toolOrientation->x(),
                                                       map.toolOrientation->y(), map.toolOrientation->z())
                                         : std::string(),
                     emax / kUm, rms / kUm);
    // Cells.
    for (long ku = 0; ku < au.count; ++ku)
        for (long kv = 0; kv < av.count; ++kv) {
            const MapPoint& p = point(ku, kv);
            const double u = au.value(ku), v = av.value(kv);
            const std::string fill = p.ok ? shade(p.error.norm() / kUm) : "#d0d0d0";
            s += fmt::format("<rect x=\"{:.2f}\" y=\"{:.2f}\" width=\"{:.2f}\" height=\"{:.2f}\" fill=\"{}\" stroke=\"{}\" stroke-width=\"0.3\"/>\n",
                             X(u - au.step / 2), Y(v + av.step / 2), au.step * sx, av.step * sy, fill, fill);
        }
    // Arrows: the in-plane error components, when both plane axes are tip coordinates X, Y, Z.
    const auto comp = [&](const std::string& a) -> int {
        if (a == "X") return 0;
        if (a == "Y") return 1;
        if (a == "Z") return 2;
        return -1;
    };
    const int cu = comp(plane.u), cv = comp(plane.v);
    std::string arrowNote = map.toolOrientation || (cu >= 0 && cv >= 0)
                                ? "no arrows: the error is zero on this whole plane"
                                : "no arrows: a plane axis is not a linear axis X, Y or Z";
    if (n == 0) arrowNote = "no point of this plane could be evaluated";
    if (emax == 0 && n > 0)
        s += fmt::format("<text x=\"{:.2f}\" y=\"{:.2f}\" font-size=\"18\" text-anchor=\"middle\" fill=\"white\">no error on this "
                         "plane: |e| = 0 everywhere</text>\n",
                         left + pw / 2, top + ph / 2);
    if (cu >= 0 && cv >= 0 && emax > 0) {
        s += "<g clip-path=\"url(#" + id + "-frame)\">\n";
        const long every = std::max<long>(1, (std::max(au.count, av.count) + 15) / 16);
        const double cell = std::min(au.step * sx, av.step * sy) * every;
        const double scale = 0.9 * cell / emax;  // px per mm of error
        for (long ku = every / 2; ku < au.count; ku += every)
            for (long kv = every / 2; kv < av.count; kv += every) {
                const MapPoint& p = point(ku, kv);
                if (!p.ok) continue;
                const double x0 = X(au.value(ku)), y0 = Y(av.value(kv));
                const double dx = p.error[cu] * scale, dy = -p.error[cv] * scale;
                if (std::hypot(dx, dy) < 1.5) {
                    s += fmt::format("<circle cx=\"{:.2f}\" cy=\"{:.2f}\" r=\"1\" fill=\"white\"/>\n", x0, y0);
                    continue;
                }
                s += fmt::format("<line x1=\"{:.2f}\" y1=\"{:.2f}\" x2=\"{:.2f}\" y2=\"{:.2f}\" stroke=\"white\" stroke-width=\"1.6\" marker-end=\"url(#{}-head)\"/>\n",
                                 x0 - dx / 2, y0 - dy / 2, x0 + dx / 2, y0 + dy / 2, id);
            }
        s += "</g>\n";
        // A reference arrow with a round length under the plot.
        const double ref = niceStep(0, 0.5 * emax / kUm, 1);
        const double ry = top + ph + 66, rx = left + 270;
        s += fmt::format("<line x1=\"{:.2f}\" y1=\"{:.2f}\" x2=\"{:.2f}\" y2=\"{:.2f}\" stroke=\"black\" stroke-width=\"1.6\" marker-end=\"url(#{}-head)\"/>"
                         "<text x=\"{:.2f}\" y=\"{:.2f}\" font-size=\"12\">= {:g} µm</text>\n",
                         rx, ry - 4, rx + ref * kUm * scale, ry - 4, id, rx + ref * kUm * scale + 8, ry, ref);
        arrowNote = fmt::format("arrows: in-plane error (e{}, e{}), scale:", plane.u == "X" ? "x" : plane.u == "Y" ? "y" : "z",
                                plane.v == "X" ? "x" : plane.v == "Y" ? "y" : "z");
    }
    // Frame and ticks.
    s += fmt::format("<rect x=\"{:.2f}\" y=\"{:.2f}\" width=\"{:.2f}\" height=\"{:.2f}\" fill=\"none\" stroke=\"black\"/>\n",
                     left, top, pw, ph);
    const double tu = niceStep(au.from, au.to, 8), tv = niceStep(av.from, av.to, 8);
    for (double u = std::ceil(uLo / tu) * tu; u <= uHi + 1e-9; u += tu)
        s += fmt::format("<line x1=\"{0:.2f}\" y1=\"{1:.2f}\" x2=\"{0:.2f}\" y2=\"{2:.2f}\" stroke=\"black\"/>"
                         "<text x=\"{0:.2f}\" y=\"{3:.2f}\" font-size=\"12\" text-anchor=\"middle\">{4:g}</text>\n",
                         X(u), top + ph, top + ph + 6, top + ph + 21, std::abs(u) < 1e-9 * tu ? 0.0 : u);
    for (double v = std::ceil(vLo / tv) * tv; v <= vHi + 1e-9; v += tv)
        s += fmt::format("<line x1=\"{0:.2f}\" y1=\"{1:.2f}\" x2=\"{2:.2f}\" y2=\"{1:.2f}\" stroke=\"black\"/>"
                         "<text x=\"{3:.2f}\" y=\"{4:.2f}\" font-size=\"12\" text-anchor=\"end\">{5:g}</text>\n",
                         left - 6, Y(v), left, left - 9, Y(v) + 4, std::abs(v) < 1e-9 * tv ? 0.0 : v);
    s += fmt::format("<text x=\"{:.2f}\" y=\"{:.2f}\" font-size=\"14\" text-anchor=\"middle\">{}</text>\n", left + pw / 2,
                     top + ph + 44, escape(axisLabel(m, map, plane.u)));
    s += fmt::format("<text x=\"{0:.2f}\" y=\"{1:.2f}\" font-size=\"14\" text-anchor=\"middle\" transform=\"rotate(-90 {0:.2f} {1:.2f})\">{2}</text>\n",
                     left - 56, top + ph / 2, escape(axisLabel(m, map, plane.v)));
    s += fmt::format("<text x=\"{:.2f}\" y=\"{:.2f}\" font-size=\"12\">{}</text>\n", left, top + ph + 66, escape(arrowNote));
    // Colour bar.
    const double bx = left + pw + 40, bh = std::min(ph, 400.0);
    s += fmt::format("<rect x=\"{:.2f}\" y=\"{:.2f}\" width=\"22\" height=\"{:.2f}\" fill=\"url(#{}-bar)\" stroke=\"black\"/>\n", bx, top, bh, id);
    for (double c = clo; c <= ctop + 1e-9 * std::abs(ctop); c += cstep) {
        const double y = top + bh - (c - clo) / (ctop - clo) * bh;
        s += fmt::format("<line x1=\"{0:.2f}\" y1=\"{1:.2f}\" x2=\"{2:.2f}\" y2=\"{1:.2f}\" stroke=\"black\"/>"
                         "<text x=\"{3:.2f}\" y=\"{4:.2f}\" font-size=\"12\">{5:g}</text>\n",
                         bx + 22, y, bx + 28, bx + 31, y + 4, c);
    }
    s += fmt::format("<text x=\"{:.2f}\" y=\"{:.2f}\" font-size=\"13\">|e| (µm)</text>\n", bx - 4, top - 10);
    s += "</svg>\n";
    return s;
}

}  // namespace

std::string renderMapSvg(const VolumetricMap& map, const MachineModel& m, const MapPlane& plane, const SvgInfo& info) {
    return render(map, nullptr, m, plane, info);
}

std::string renderMapSvg(const VolumetricMap& map, const std::vector<MapPoint>& planePoints, const MachineModel& m,
                         const MapPlane& plane, const SvgInfo& info) {
    return render(map, &planePoints, m, plane, info);
}

}  // namespace cnccomp::io
