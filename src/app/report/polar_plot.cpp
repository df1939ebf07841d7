#include "app/report/polar_plot.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/markup.hpp"
#include "app/report/report_format.hpp"

namespace cnccomp::app::report {
using namespace cnccomp::io;

PolarScale polarScale(const RunSection& run) {
    double m = 0;
    for (const PolarPass& p : run.passes) {
        for (double v : p.before)
            if (std::isfinite(v)) m = std::max(m, std::abs(v));
        for (double v : p.after)
            if (std::isfinite(v)) m = std::max(m, std::abs(v));
    }
    const double fullUm = std::max(m / kUm, 0.1);
    PolarScale s;
    s.ringUm = niceNumber(fullUm / 3.0);
    s.rings = std::max(1, static_cast<int>(std::ceil(fullUm / s.ringUm - 1e-9)));
    s.pxPerUm = kPolarBandPx / (s.rings * s.ringUm);
    return s;
}

PolarPixel polarPixel(const PolarScale& s, double angleDeg, double dL) {
    const double r = kPolarNominalPx + dL / kUm * s.pxPerUm;
    const double a = angleDeg * kDeg;
    return {kPolarCx + r * std::cos(a), kPolarCy - r * std::sin(a)};
}

namespace {

std::string polyline(const PolarScale& s, const std::vector<double>& angles, const std::vector<double>& dL) {
    std::string pts;
    for (size_t i = 0; i < angles.size() && i < dL.size(); ++i) {
        if (!std::isfinite(angles[i]) || !std::isfinite(dL[i])) continue;
        const PolarPixel p = polarPixel(s, angles[i], dL[i]);
        pts += fmt::format("{}{:.2f},{:.2f}", pts.empty() ? "" : " ", p.x, p.y);
    }
    return pts;
}

}  // namespace

std::string renderPolarPlot(const RunSection& run, const std::string& idPrefix) {
    const PolarScale sc = polarScale(run);
    const std::string id = escapeXml(idPrefix, "plot id");
    std::string s = fmt::format(R"(<svg xmlns="http://www.w3.org/2000/svg" width="{0}" height="{1}" viewBox="0 0 {0} {1}" font-family="Helvetica, Arial, sans-serif" id="{2}">)",
                                kPolarWidth, kPolarHeight, id);
    s += "\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
    s += fmt::format("<text x=\"16\" y=\"26\" font-size=\"18\" font-weight=\"bold\">{}</text>\n",
                     escapeXml(run.name + (run.test.empty() || run.test == run.name ? "" : " (" + run.test + ")"), "run name"));
    s += fmt::format("<text x=\"16\" y=\"46\" font-size=\"12\">nominal radius LB = {:g} mm; radial deviation magnified, "
                     "{:g} µm per ring</text>\n",
                     run.LB, sc.ringUm);
    // Spokes and angle labels.
    const double outer = kPolarNominalPx + kPolarBandPx, inner = std::max(10.0, kPolarNominalPx - kPolarBandPx);
    for (int a = 0; a < 360; a += 30) {
        const double c = std::cos(a * kDeg), si = std::sin(a * kDeg);
        s += fmt::format("<line x1=\"{:.2f}\" y1=\"{:.2f}\" x2=\"{:.2f}\" y2=\"{:.2f}\" stroke=\"#d8d8d8\" stroke-width=\"0.8\"/>\n",
                         kPolarCx + inner * c, kPolarCy - inner * si, kPolarCx + outer * c, kPolarCy - outer * si);
        if (a % 90 == 0)
            s += fmt::format("<text x=\"{:.2f}\" y=\"{:.2f}\" font-size=\"12\" text-anchor=\"middle\" fill=\"#555\">{}°</text>\n",
                             kPolarCx + (outer + 16) * c, kPolarCy - (outer + 16) * si + 4, a);
    }
    // Scale rings: dashed, the nominal circle solid.
    for (int k = -sc.rings; k <= sc.rings; ++k) {
        const double r = kPolarNominalPx + k * sc.ringUm * sc.pxPerUm;
        if (r <= 0) continue;
        s += fmt::format("<circle cx=\"{}\" cy=\"{}\" r=\"{:.2f}\" fill=\"none\" stroke=\"{}\" stroke-width=\"{}\"{}/>\n",
                         kPolarCx, kPolarCy, r, k == 0 ? "#555" : "#bbbbbb", k == 0 ? "1.2" : "0.8",
                         k == 0 ? "" : " stroke-dasharray=\"4 3\"");
        if (k != 0)
            s += fmt::format("<text x=\"{:.2f}\" y=\"{:.2f}\" font-size=\"10\" fill=\"#777\">{:+g}</text>\n",
                             kPolarCx + 0.259 * r + 2, kPolarCy - 0.966 * r - 2, k * sc.ringUm);  // at 75°
    }
    // Traces: before first, after on top.
    struct Legend {
        const char* colour;
        std::string label;
    };
    std::vector<Legend> legend;
    const auto addLegend = [&](const char* c, const std::string& l) {
        for (const Legend& e : legend)
            if (e.label == l) return;
        legend.push_back({c, l});
    };
    // CW wide and first, CCW narrow on top: where the passes coincide (no hysteresis) both colours stay visible.
    for (int direction : {-1, +1})
        for (int after = 0; after < 2; ++after)
            for (const PolarPass& p : run.passes) {
                const std::vector<double>& v = after ? p.after : p.before;
                if (v.empty() || (p.direction > 0) != (direction > 0)) continue;
                const char* colour = p.direction > 0 ? (after ? kCcwAfter : kCcwBefore) : (after ? kCwAfter : kCwBefore);
                s += fmt::format("<polyline fill=\"none\" stroke=\"{}\" stroke-width=\"{}\" stroke-linejoin=\"round\" points=\"{}\"/>\n",
                                 colour, p.direction > 0 ? kPolarCcwWidthPx : kPolarCwWidthPx, polyline(sc, p.angleDeg, v));
                addLegend(colour, fmt::format("{} {}", p.direction > 0 ? "CCW" : "CW", after ? "after compensation" : "before"));
            }
    // Legend and the ISO 230-4 figures.
    double y = kPolarCy + outer + 40;
    for (size_t i = 0; i < legend.size(); ++i) {
        const double x = 16 + static_cast<double>(i % 2) * 270, yy = y + static_cast<double>(i / 2) * 18;
        s += fmt::format("<line x1=\"{:.1f}\" y1=\"{:.1f}\" x2=\"{:.1f}\" y2=\"{:.1f}\" stroke=\"{}\" stroke-width=\"3\"/>"
                         "<text x=\"{:.1f}\" y=\"{:.1f}\" font-size=\"12\">{}</text>\n",
                         x, yy - 4, x + 24, yy - 4, legend[i].colour, x + 30, yy, escapeXml(legend[i].label));
    }
    y += static_cast<double>((legend.size() + 1) / 2) * 18 + 8;
    const auto line = [&](const char* label, const IsoFigures& f) {
        const auto v = [](double x, int decimals, const char* unit) {
            return std::isfinite(x) ? fixed(x, decimals) + " " + unit : fixed(x, decimals);
        };
        s += fmt::format("<text x=\"16\" y=\"{:.1f}\" font-size=\"12\">{}: G {}, F max {}, F min {}, mean radius {}, H {}</text>\n",
                         y, label, v(f.G / kUm, 2, "µm"), v(f.Fmax / kUm, 2, "µm"), v(f.Fmin / kUm, 2, "µm"),
                         v(f.meanRadius, 5, "mm"), v(f.H / kUm, 2, "µm"));
        y += 17;
    };
    line("before", run.before);
    if (std::isfinite(run.after.G)) line("after", run.after);
    s += "</svg>\n";
    return s;
}

}  // namespace cnccomp::app::report
