#pragma once
// The HTML report: one self-contained page (inline CSS and SVG, no script, nothing loaded from anywhere) with the
// polar plot and ISO 230-4 figures of every ball-bar run, the deviations with their 95 % intervals and the
// unidentified ones named, the volumetric maps on one colour scale from 0, and the controller files with their
// coverage and residual. Every plot is also written as its own SVG beside the page, and the numbers as a JSON
// summary (schema "cnccomp-report-summary/1"), which the page also carries in a <script type="application/json">.
#include <string>
#include <vector>

#include "cnccomp/io/output_set.hpp"
#include "app/report/report_data.hpp"

namespace cnccomp::app::report {

/// The files of one report.
struct ReportFiles {
    std::string html;                ///< the page
    std::string summary;             ///< <stem>.summary.json
    std::vector<std::string> plots;  ///< <stem>-polar-<run>.svg per run, <stem>-map-<k>.svg per map, in page order
};

/// True for a path ending in .html or .htm (any case): the commands' --report writes the page there.
bool isHtmlPath(const std::string& path);

/// File names for a page path: "out/report.html" → out/report.summary.json, out/report-polar-<run>.svg,
/// out/report-map-1.svg, … (run names must be plain file names: InputError otherwise).
ReportFiles reportFiles(const std::string& htmlPath, const ReportData& data);

/// Stages the page, the SVGs and the summary in `out`; nothing is written before out.commit(), so a command that
/// fails later leaves none of them. Throws ModelError for maps without data.machineModel.
ReportFiles stageHtmlReport(io::OutputSet& out, const std::string& htmlPath, const ReportData& data);

/// The three kinds of text, for tests.
std::string formatReportSummaryJson(const ReportData& data, const ReportFiles& files);
/// SVG of every plot in page order (runs, then maps), with ids unique on the page.
std::vector<std::string> renderReportPlots(const ReportData& data);
std::string formatHtmlReport(const ReportData& data, const ReportFiles& files, const std::vector<std::string>& plots);

}  // namespace cnccomp::app::report
