#include "app/report/html_report.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/markup.hpp"
#include "app/report/polar_plot.hpp"
#include "app/report/report_format.hpp"

namespace cnccomp::app::report {
using namespace cnccomp::io;
namespace fs = std::filesystem;

namespace {

std::string esc(std::string_view s) { return escapeXml(s, "report text"); }
/// Numbers in the report's embedded JSON: 9 significant digits.
std::string reportNumber(double v) { return jsonNumber(v, 9); }

/// Largest |e| over every map's plane, µm: the shared top of the colour scale.
double sharedScaleUm(const ReportData& d) {
    double m = 0;
    for (const MapPicture& p : d.maps) m = std::max(m, planeMaxError(p.map, p.plane) / kUm);
    return m;
}

std::string isoJson(const IsoFigures& f) {
    return fmt::format(R"({{"G_um": {}, "F_max_um": {}, "F_min_um": {}, "mean_radius_mm": {}, "H_um": {}}})",
                       reportNumber(f.G / kUm), reportNumber(f.Fmax / kUm), reportNumber(f.Fmin / kUm), reportNumber(f.meanRadius),
                       reportNumber(f.H / kUm));
}

template <class T, class F>
std::string jsonArray(const std::vector<T>& v, F item) {
    std::string o = "[";
    for (size_t i = 0; i < v.size(); ++i) o += (i ? ", " : "") + item(v[i]);
    return o + "]";
}

std::string fileName(const std::string& path) { return fs::path(path).filename().string(); }

const char* kStyle = R"(
body { font-family: Helvetica, Arial, sans-serif; margin: 24px; color: #222; max-width: 1800px; }
h1 { font-size: 24px; margin-bottom: 4px; } h2 { font-size: 19px; margin-top: 32px; border-bottom: 1px solid #ccc; }
table { border-collapse: collapse; margin: 8px 0; font-size: 13px; }
th, td { border: 1px solid #ccc; padding: 3px 8px; text-align: right; }
th { background: #f2f2f2; } td.l, th.l { text-align: left; }
.facts td { text-align: left; border: none; padding: 1px 12px 1px 0; }
.alarm { background: #c00000; color: white; font-weight: bold; font-size: 20px; padding: 14px 18px; margin: 0 0 12px 0;
         border: 3px solid #700000; }
.warn { background: #fff4e0; border: 1px solid #f0c070; padding: 6px 10px; margin: 4px 0; font-size: 13px; }
.plots { display: flex; flex-wrap: wrap; gap: 12px; }
figure { margin: 0; border: 1px solid #ddd; padding: 4px; background: white; }
figcaption { font-size: 12px; color: #555; max-width: 600px; }
.map svg { width: 640px; height: auto; }
.no { color: #a33; }
)";

}  // namespace

bool isHtmlPath(const std::string& path) {
    std::string ext = fs::path(path).extension().string();
    for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return ext == ".html" || ext == ".htm";
}

ReportFiles reportFiles(const std::string& htmlPath, const ReportData& data) {
    const fs::path p(htmlPath);
    const std::string dir = p.has_parent_path() ? p.parent_path().string() : std::string(".");
    const std::string stem = p.stem().string();
    ReportFiles f;
    f.html = htmlPath;
    f.summary = OutputSet::fileIn(dir, stem + ".summary.json", htmlPath);
    for (const RunSection& r : data.runs) f.plots.push_back(OutputSet::fileIn(dir, stem + "-polar-" + r.name + ".svg", htmlPath));
    for (size_t k = 0; k < data.maps.size(); ++k)
        f.plots.push_back(OutputSet::fileIn(dir, fmt::format("{}-map-{}.svg", stem, k + 1), htmlPath));
    return f;
}

std::vector<std::string> renderReportPlots(const ReportData& d) {
    std::vector<std::string> out;
    for (size_t i = 0; i < d.runs.size(); ++i) out.push_back(renderPolarPlot(d.runs[i], fmt::format("polar{}", i + 1)));
    if (!d.maps.empty() && !d.machineModel) throw ModelError("report: maps need the machine model (ReportData::machineModel)");
    const double scale = sharedScaleUm(d);
    for (size_t k = 0; k < d.maps.size(); ++k) {
        SvgInfo info;
        info.title = d.maps[k].title;
        info.scaleMaxUm = scale;
        info.idPrefix = fmt::format("map{}", k + 1);
        out.push_back(renderMapSvg(d.maps[k].map, *d.machineModel, d.maps[k].plane, info));
    }
    return out;
}

namespace {

/// `  "key": [` then one row a line (`row(item, index)`, a JSON object) and `],`: the summary's tables.
template <class T, class Row>
void appendRows(std::string& o, const char* key, const std::vector<T>& items, Row row) {
    o += fmt::format("  \"{}\": [", key);
    for (size_t i = 0; i < items.size(); ++i) o += (i ? ",\n    " : "\n    ") + row(items[i], i);
    o += items.empty() ? "],\n" : "\n  ],\n";
}

}  // namespace

std::string formatReportSummaryJson(const ReportData& d, const ReportFiles& files) {
    std::string o = "{\n  \"schema\": \"cnccomp-report-summary/1\",\n";
    o += fmt::format("  \"title\": {},\n  \"machine\": {},\n", jsonString(d.title), jsonString(d.machine));
    o += "  \"facts\": " + jsonArray(d.facts, [](const auto& f) {
             return fmt::format("[{}, {}]", jsonString(f.first), jsonString(f.second));
         }) + ",\n";
    o += "  \"alarms\": " + jsonArray(d.alarms, [](const std::string& w) { return jsonString(w); }) + ",\n";
    o += "  \"warnings\": " + jsonArray(d.warnings, [](const std::string& w) { return jsonString(w); }) + ",\n";
    o += "  \"after_note\": " + jsonString(d.afterNote) + ",\n";
    appendRows(o, "runs", d.runs, [&](const RunSection& r, size_t i) {
        int samples = 0;
        for (const PolarPass& p : r.passes) samples += static_cast<int>(p.before.size());
        return fmt::format("{{\"name\": {}, \"test\": {}, \"LB_mm\": {}, \"samples\": {}, \"passes\": {}, \"before\": {}, "
                           "\"after\": {}, \"rms_before_um\": {}, \"rms_after_um\": {}, \"plot\": {}}}",
                           jsonString(r.name), jsonString(r.test), reportNumber(r.LB), samples,
                           jsonArray(r.passes, [](const PolarPass& p) { return jsonString(p.direction > 0 ? "ccw" : "cw"); }),
                           isoJson(r.before), isoJson(r.after), reportNumber(r.rmsBefore / kUm), reportNumber(r.rmsAfter / kUm),
                           jsonString(i < files.plots.size() ? fileName(files.plots[i]) : ""));
    });
    appendRows(o, "tables", d.tables, [](const TableSection& t, size_t) {
        const auto cells = [](const std::vector<std::string>& v) { return jsonArray(v, [](const std::string& c) { return jsonString(c); }); };
        return fmt::format("{{\"title\": {}, \"header\": {}, \"rows\": {}, \"notes\": {}}}", jsonString(t.title), cells(t.header),
                           jsonArray(t.rows, cells), cells(t.notes));
    });
    appendRows(o, "spans", d.spans, [](const PassSpan& p, size_t) {
        return fmt::format("{{\"run\": {}, \"type\": {}, \"pass\": {}, \"quantity\": {}, \"before_um\": {}, \"after_um\": {}, "
                           "\"warning\": {}}}",
                           jsonString(p.run), jsonString(p.type), jsonString(p.pass), jsonString(p.quantity),
                           reportNumber(p.before / kUm), reportNumber(p.after / kUm), p.warning.empty() ? "null" : jsonString(p.warning));
    });
    appendRows(o, "deviations", d.deviations, [](const DeviationRow& r, size_t) {
        return fmt::format("{{\"name\": {}, \"alias\": {}, \"unit\": {}, \"identified\": {}, \"value\": {}, \"low95\": {}, "
                           "\"high95\": {}, \"truth\": {}}}",
                           jsonString(r.name), jsonString(r.alias), jsonString(r.unit), r.identified ? "true" : "false",
                           reportNumber(r.value), reportNumber(r.low95), reportNumber(r.high95), reportNumber(r.truth));
    });
    std::vector<std::string> unidentified;
    for (const DeviationRow& r : d.deviations)
        if (!r.identified) unidentified.push_back(r.name);
    o += "  \"unidentified\": " + jsonArray(unidentified, [](const std::string& s) { return jsonString(s); }) + ",\n";
    o += "  \"combinations\": " + jsonArray(d.combinations, [](const std::string& s) { return jsonString(s); }) + ",\n";
    o += fmt::format("  \"map_scale_max_um\": {},\n", reportNumber(d.maps.empty() ? kUnknown : sharedScaleUm(d)));
    appendRows(o, "maps", d.maps, [&](const MapPicture& m, size_t k) {
        const size_t plot = d.runs.size() + k;
        return fmt::format("{{\"title\": {}, \"plane_max_um\": {}, \"max_um\": {}, \"rms_um\": {}, \"points\": {}, \"plot\": {}}}",
                           jsonString(m.title), reportNumber(planeMaxError(m.map, m.plane) / kUm),
                           reportNumber(m.map.stats.norm.maxAbs / kUm), reportNumber(m.map.stats.norm.rms / kUm), m.map.stats.points,
                           jsonString(plot < files.plots.size() ? fileName(files.plots[plot]) : ""));
    });
    appendRows(o, "controllers", d.controllers, [](const ControllerSection& c, size_t) {
        const auto names = [](const std::vector<CoverageRow>& v) {
            return jsonArray(v, [](const CoverageRow& r) { return jsonString(r.deviation); });
        };
        const std::string remaining = jsonArray(c.notCompensated, [](const CoverageRow& r) {
            return fmt::format("{{\"deviation\": {}, \"value\": {}, \"unit\": {}, \"alias\": {}, \"alias_value\": {}, "
                               "\"reason\": {}}}",
                               jsonString(r.deviation), reportNumber(r.value), jsonString(r.unit),
                               r.alias.empty() ? "null" : jsonString(r.alias), reportNumber(r.aliasValue), jsonString(r.note));
        });
        return fmt::format("{{\"name\": {}, \"files\": {}, \"compensated\": {}, \"not_compensated\": {}, "
                           "\"before_max_um\": {}, \"before_rms_um\": {}, \"after_max_um\": {}, \"after_rms_um\": {}, \"points\": {}, "
                           "\"span_before_um\": {}, \"span_after_um\": {}, \"basis\": {},\n     \"remaining\": {}}}",
                           jsonString(c.name), jsonArray(c.files, [](const std::string& s) { return jsonString(s); }),
                           names(c.compensated), names(c.notCompensated), reportNumber(c.beforeMax / kUm),
                           reportNumber(c.beforeRms / kUm), reportNumber(c.afterMax / kUm), reportNumber(c.afterRms / kUm), c.points,
                           reportNumber(c.spanBefore / kUm), reportNumber(c.spanAfter / kUm), jsonString(c.basis), remaining);
    });
    o += "  \"files\": {\"html\": " + jsonString(fileName(files.html)) + ", \"plots\": " +
         jsonArray(files.plots, [](const std::string& s) { return jsonString(fileName(s)); }) + "}\n}\n";
    return o;
}

std::string formatHtmlReport(const ReportData& d, const ReportFiles& files, const std::vector<std::string>& plots) {
    if (plots.size() != d.runs.size() + d.maps.size() || files.plots.size() != plots.size())
        throw ModelError(fmt::format("report: {} plots and {} plot files for {} runs and {} maps", plots.size(),
                                     files.plots.size(), d.runs.size(), d.maps.size()));
    std::string h = "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n";
    h += fmt::format("<title>{}</title>\n<style>{}</style>\n</head>\n<body>\n", esc(d.title), kStyle);
    for (const std::string& a : d.alarms) h += fmt::format("<div class=\"alarm\" role=\"alert\">{}</div>\n", esc(a));
    h += fmt::format("<h1>{}</h1>\n<table class=\"facts\">\n<tr><td>machine</td><td>{}</td></tr>\n", esc(d.title), esc(d.machine));
    for (const auto& [k, v] : d.facts) h += fmt::format("<tr><td>{}</td><td>{}</td></tr>\n", esc(k), esc(v));
    h += "</table>\n";
    for (const std::string& w : d.warnings) h += fmt::format("<div class=\"warn\">warning: {}</div>\n", esc(w));

    if (!d.runs.empty()) {
        const bool rms = std::any_of(d.runs.begin(), d.runs.end(), [](const RunSection& r) {
            return std::isfinite(r.rmsBefore) || std::isfinite(r.rmsAfter);
        });
        h += "<h2>Ball-bar runs: ISO 230-4 circular test figures</h2>\n<table>\n<tr><th class=\"l\">run</th><th class=\"l\">test</th>"
             "<th>passes</th><th>G before µm</th><th>G after µm</th><th>F max before µm</th><th>F min before µm</th><th>F max after µm</th>"
             "<th>F min after µm</th><th>mean radius mm</th><th>H before µm</th><th>H after µm</th>";
        h += rms ? "<th>fit RMS before µm</th><th>fit RMS after µm</th></tr>\n" : "</tr>\n";
        for (const RunSection& r : d.runs) {
            std::string passes;
            for (const PolarPass& p : r.passes) passes += std::string(passes.empty() ? "" : " ") + (p.direction > 0 ? "CCW" : "CW");
            h += fmt::format("<tr><td class=\"l\">{}</td><td class=\"l\">{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td>"
                             "<td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td>",
                             esc(r.name), esc(r.test), passes, fixed(r.before.G / kUm, 2), fixed(r.after.G / kUm, 2),
                             fixed(r.before.Fmax / kUm, 2), fixed(r.before.Fmin / kUm, 2), fixed(r.after.Fmax / kUm, 2),
                             fixed(r.after.Fmin / kUm, 2), fixed(r.before.meanRadius, 5), fixed(r.before.H / kUm, 2),
                             fixed(r.after.H / kUm, 2));
            h += rms ? fmt::format("<td>{}</td><td>{}</td></tr>\n", fixed(r.rmsBefore / kUm, 3), fixed(r.rmsAfter / kUm, 3))
                     : std::string("</tr>\n");
        }
        h += fmt::format("</table>\n<p style=\"font-size:12px\">G circular deviation, F radial deviation about the nominal centre, H "
                         "circular hysteresis (CCW against CW), after ISO 230-4.{}</p>\n<div class=\"plots\">\n",
                         d.afterNote.empty() ? "" : " \"after\": " + esc(d.afterNote) + ".");
        for (size_t i = 0; i < d.runs.size(); ++i) {
            h += "<figure>\n" + plots[i];
            std::string caption = fmt::format("{}", esc(fileName(files.plots[i])));
            for (const std::string& n : d.runs[i].notes) caption += "<br>" + esc(n);
            h += fmt::format("<figcaption>{}</figcaption>\n</figure>\n", caption);
        }
        h += "</div>\n";
    }

    for (const TableSection& t : d.tables) {
        h += fmt::format("<h2>{}</h2>\n<table>\n<tr>", esc(t.title));
        for (const std::string& c : t.header) h += "<th class=\"l\">" + esc(c) + "</th>";
        h += "</tr>\n";
        for (const auto& row : t.rows) {
            h += "<tr>";
            for (const std::string& c : row) h += "<td class=\"l\">" + esc(c) + "</td>";
            h += "</tr>\n";
        }
        h += "</table>\n";
        for (const std::string& n : t.notes) h += "<p style=\"font-size:12px\">" + esc(n) + "</p>\n";
    }

    if (!d.spans.empty()) {
        h += "<h2>Instrument readings per pass: span before and after</h2>\n<table>\n<tr><th class=\"l\">run</th>"
             "<th class=\"l\">type</th><th class=\"l\">pass</th><th class=\"l\">reading</th><th>span before µm</th>"
             "<th>span after µm</th><th class=\"l\">warning</th></tr>\n";
        for (const PassSpan& p : d.spans)
            h += fmt::format("<tr><td class=\"l\">{}</td><td class=\"l\">{}</td><td class=\"l\">{}</td><td class=\"l\">{}</td>"
                             "<td>{}</td><td>{}</td><td class=\"l\">{}</td></tr>\n",
                             esc(p.run), esc(p.type), esc(p.pass), p.quantity == "dL" ? "ΔL" : esc(p.quantity),
                             fixed(p.before / kUm, 3), fixed(p.after / kUm, 3), esc(p.warning));
        h += "</table>\n<p style=\"font-size:12px\">span = max − min of the reading over the pass (ball bar: ΔL = L − LB; "
             "R-test: the largest span of a displacement component).</p>\n";
    }

    if (!d.deviations.empty()) {
        bool truth = false;
        for (const DeviationRow& r : d.deviations) truth = truth || std::isfinite(r.truth);
        h += fmt::format("<h2>Deviations</h2>\n<table>\n<tr><th class=\"l\">name</th><th class=\"l\">alias</th><th>value</th>"
                         "<th>95 % low</th><th>95 % high</th>{}<th class=\"l\">unit</th></tr>\n",
                         truth ? "<th>truth</th>" : "");
        std::vector<std::string> missing;
        for (const DeviationRow& r : d.deviations) {
            if (!r.identified) {
                missing.push_back(r.name + (r.alias.empty() ? "" : " (" + r.alias + ")"));
                continue;
            }
            h += fmt::format("<tr><td class=\"l\">{}</td><td class=\"l\">{}</td><td>{}</td><td>{}</td><td>{}</td>{}<td class=\"l\">{}</td></tr>\n",
                             esc(r.name), esc(r.alias), fixed(r.value, 3), fixed(r.low95, 3), fixed(r.high95, 3),
                             truth ? "<td>" + fixed(r.truth, 3) + "</td>" : "", r.unit == "um" ? "µm" : esc(r.unit));
        }
        h += "</table>\n";
        if (!missing.empty()) {
            h += "<p class=\"no\">Not identified (these measurements cannot tell them apart, or do not see them): ";
            for (size_t i = 0; i < missing.size(); ++i) h += (i ? ", " : "") + esc(missing[i]);
            h += "</p>\n";
        }
        if (!d.combinations.empty()) {
            h += "<p>Identifiable combinations of the unidentified deviations:</p>\n<ul>\n";
            for (const std::string& c : d.combinations) h += "<li>" + esc(c) + "</li>\n";
            h += "</ul>\n";
        }
    }

    if (!d.maps.empty()) {
        h += fmt::format("<h2>Volumetric error maps</h2>\n<p style=\"font-size:12px\">One colour scale for every map: 0 to {} µm.</p>\n"
                         "<div class=\"plots\">\n",
                         fixed(sharedScaleUm(d), 2));
        for (size_t k = 0; k < d.maps.size(); ++k) {
            const size_t i = d.runs.size() + k;
            h += fmt::format("<figure class=\"map\">\n{}<figcaption>{} — {}</figcaption>\n</figure>\n", plots[i],
                             esc(d.maps[k].title), esc(fileName(files.plots[i])));
        }
        h += "</div>\n";
    }

    if (!d.controllers.empty()) {
        const bool spans = std::any_of(d.controllers.begin(), d.controllers.end(), [](const ControllerSection& c) {
            return std::isfinite(c.spanBefore) || std::isfinite(c.spanAfter);
        });
        h += "<h2>Compensation</h2>\n<table>\n<tr><th class=\"l\">controller</th><th class=\"l\">files</th><th>compensated</th>"
             "<th>not compensated</th>";
        h += spans ? "<th>largest ΔL span before µm</th><th>largest ΔL span after µm</th>" : "";
        h += "<th>tool-tip max before µm</th><th>tool-tip max after µm</th><th>tool-tip RMS after µm</th><th class=\"l\">basis</th></tr>\n";
        for (const ControllerSection& c : d.controllers) {
            std::string files;
            for (const std::string& f : c.files) files += (files.empty() ? "" : "<br>") + esc(f);
            h += fmt::format("<tr><td class=\"l\">{}</td><td class=\"l\">{}</td><td>{}</td><td>{}</td>", esc(c.name),
                             files.empty() ? "(not written)" : files, c.compensated.size(), c.notCompensated.size());
            if (spans) h += fmt::format("<td>{}</td><td>{}</td>", fixed(c.spanBefore / kUm, 3), fixed(c.spanAfter / kUm, 3));
            h += fmt::format("<td>{}</td><td>{}</td><td>{}</td><td class=\"l\">{}</td></tr>\n", fixed(c.beforeMax / kUm, 2),
                             fixed(c.afterMax / kUm, 2), fixed(c.afterRms / kUm, 2), esc(c.basis));
        }
        h += "</table>\n";
        for (const ControllerSection& c : d.controllers) {
            if (c.notCompensated.empty()) continue;
            const bool values = std::any_of(c.notCompensated.begin(), c.notCompensated.end(),
                                            [](const CoverageRow& r) { return std::isfinite(r.value); });
            if (values) {  // the deviations left, with their value in the machine the figures are for
                // ISO value under the ISO name, the alias' own value under the alias: what an engineer adjusts by hand.
                h += fmt::format("<p class=\"no\">Deviations {} leaves, and why (value under the ISO 230-1 name, and under the "
                                 "paper alias where the machine has one):</p>\n<table>\n<tr><th class=\"l\">deviation</th>"
                                 "<th>ISO value</th><th class=\"l\">unit</th><th class=\"l\">paper alias</th><th>alias value</th>"
                                 "<th class=\"l\">why not compensated</th></tr>\n",
                                 esc(c.name));
                for (const CoverageRow& r : c.notCompensated)
                    h += fmt::format("<tr><td class=\"l\">{}</td><td>{}</td><td class=\"l\">{}</td><td class=\"l\">{}</td><td>{}</td>"
                                     "<td class=\"l\">{}</td></tr>\n",
                                     esc(r.deviation), fixed(r.value, 3), r.unit == "um" ? "µm" : esc(r.unit), esc(r.alias),
                                     r.alias.empty() ? "" : fixed(r.aliasValue, 3), esc(r.note));
                h += "</table>\n";
                continue;
            }
            h += fmt::format("<p class=\"no\">{} does not compensate: ", esc(c.name));
            for (size_t i = 0; i < c.notCompensated.size(); ++i)
                h += fmt::format("{}{} ({})", i ? "; " : "", esc(c.notCompensated[i].deviation), esc(c.notCompensated[i].note));
            h += "</p>\n";
        }
    }
    h += "<script type=\"application/json\" id=\"cnccomp-summary\">\n" + formatReportSummaryJson(d, files) + "</script>\n";
    h += "</body>\n</html>\n";
    return h;
}

ReportFiles stageHtmlReport(OutputSet& out, const std::string& htmlPath, const ReportData& data) {
    const ReportFiles files = reportFiles(htmlPath, data);
    const std::vector<std::string> plots = renderReportPlots(data);
    out.add(files.html, formatHtmlReport(data, files, plots));
    for (size_t i = 0; i < plots.size(); ++i) out.add(files.plots[i], plots[i]);
    out.add(files.summary, formatReportSummaryJson(data, files));
    return files;
}

}  // namespace cnccomp::app::report
