#pragma once
// The data of an HTML report (report/html_report.hpp), as plain values: whoever has the numbers fills what it has
// (identify: runs, ISO 230-4 values, deviations, maps, predicted controller sections — identification_report.hpp;
// verify: runs before/after the compensation, spans per pass, maps, the compensation used and the deviations it
// leaves — verification_report.hpp) and leaves the rest empty; empty sections and unknown columns are not shown.
//
// Units: every length in this struct is in mm and every angle in deg, except DeviationRow, which holds display
// values in its own `unit` (um or arcsec). NaN means "not known" and is shown as "–" (null in the JSON summary).
//
// Filling it:
//   ReportData d;
//   d.title = "Identification of multitasking"; d.machine = m.name; d.machineModel = &m;
//   d.facts = {{"plan", "plan.xml"}, {"solver", "levenberg-marquardt, converged"}};
//   RunSection r; r.name = "B-X"; r.test = "B-X"; r.LB = 100;
//   r.passes.push_back({+1, angles, measuredDeltaL, predictedAfter});   // one PolarPass per recorded pass
//   r.before = isoFigures(evaluateCircularRun(...));                     // ISO 230-4 (circular_test.hpp)
//   d.runs.push_back(r);
//   d.deviations.push_back({"EB0B", "bXB", "arcsec", true, 9.1, 8.7, 9.5});
//   d.maps.push_back({"before compensation", mapBefore, parseMapPlane("XY@Z=0")});
//   d.controllers.push_back({...});                                        // files written, coverage, residual
//   stageHtmlReport(outputs, "out/report.html", d);  outputs.commit();
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "cnccomp/circular_test.hpp"
#include "cnccomp/io/svg_map.hpp"
#include "cnccomp/volumetric_map.hpp"

namespace cnccomp::app::report {

inline constexpr double kUnknown = std::numeric_limits<double>::quiet_NaN();

/// One recorded pass of a ball-bar run, drawn in the polar plot.
struct PolarPass {
    int direction = +1;            ///< +1 CCW (angle increasing), −1 CW
    std::vector<double> angleDeg;  ///< sweep angle of each sample, deg (0° to the right, CCW counter-clockwise)
    std::vector<double> before;    ///< ΔL as measured (the machine as it is), mm
    std::vector<double> after;     ///< ΔL after compensation (predicted or measured again), mm; empty = not known
};

/// ISO 230-4 figures of one run (every pass), mm; NaN when not known.
struct IsoFigures {
    double G = kUnknown;           ///< circular deviation (largest of the passes)
    double Fmax = kUnknown;        ///< radial deviation F max (about the nominal centre)
    double Fmin = kUnknown;        ///< radial deviation F min
    double meanRadius = kUnknown;  ///< least-squares radius (mean of the passes)
    double H = kUnknown;           ///< circular hysteresis (needs a CCW and a CW pass)
};
IsoFigures isoFigures(const CircularRunResult& r);

struct RunSection {
    std::string name;   ///< run name of the plan (also names the plot's SVG file: a plain file name)
    std::string test;   ///< run type (B-X, C-radial, …) or kind
    double LB = 0;      ///< nominal bar length = radius of the plot's reference circle, mm
    std::vector<PolarPass> passes;
    IsoFigures before, after;  ///< `after` from the passes' `after` values, NaN without them
    double rmsBefore = kUnknown, rmsAfter = kUnknown;  ///< fit residual RMS of the run, mm (columns shown when known)
    std::vector<std::string> notes;  ///< shown under the plot (import summary, relative length offset, …)
};

/// One deviation of the machine; values in `unit` (um or arcsec).
struct DeviationRow {
    std::string name, alias, unit;
    bool identified = true;  ///< false: named in the "not identified" list, no value
    double value = kUnknown, low95 = kUnknown, high95 = kUnknown;
    double truth = kUnknown;  ///< known true value (simulations, verify), else NaN
};

/// A volumetric map on one plane. All maps of a report share one colour scale from 0 to the largest |e| of them.
struct MapPicture {
    std::string title;  ///< "before compensation", "after compensation (linuxcnc)", …
    VolumetricMap map;
    io::MapPlane plane;
};

/// What the instrument reads on one pass of a run before and after compensation (verify): the span (max − min) of ΔL
/// for a ball bar, of the largest displacement component for an R-test.
struct PassSpan {
    std::string run, type, pass;      ///< run name, run type, "CW" / "CCW" / "forward" / "reverse"
    std::string quantity;             ///< "dL" or "displacement"
    double before = kUnknown, after = kUnknown;  ///< mm
    std::string warning;              ///< e.g. the compensated commands leave an axis' travel; empty = none
};

/// One deviation a compensation takes (how) or leaves (why not), with its value where known: under its ISO 230-1 name
/// the ISO value, under the paper alias the alias' own value (verify.hpp VerifyRemaining; iso_names.hpp).
struct CoverageRow {
    std::string deviation, note;
    double value = kUnknown;          ///< ISO value in `unit` (um or arcsec), in the machine the figures are for; NaN = not shown
    std::string unit;
    std::string alias{};              ///< paper alias; empty = none
    double aliasValue = kUnknown;     ///< value under the alias, same unit
};

/// A controller's compensation: files, coverage and the predicted (or verified) residual tool-tip error.
struct ControllerSection {
    std::string name;                 ///< backend name, e.g. linuxcnc ("ideal", "corrected test programs" in verify)
    std::vector<std::string> files;   ///< paths of the files written or read; empty = not written by this command
    std::vector<CoverageRow> compensated, notCompensated;  ///< deviation, how / why not
    double beforeMax = kUnknown, beforeRms = kUnknown;  ///< tool-tip error without compensation, mm
    double afterMax = kUnknown, afterRms = kUnknown;    ///< with the controller's compensation, mm
    int points = 0;                   ///< workspace poses the figures are taken over
    double spanBefore = kUnknown, spanAfter = kUnknown; ///< largest ΔL span of the plan's runs (verify's residual), mm
    std::string basis;                ///< what the figures are ("predicted on the identified machine", …)
};

/// A table of text cells shown after the runs (e.g. the ranked diagnostics of a linear-axis circle), also in the JSON
/// summary under "tables". Cells are plain text (escaped when written).
struct TableSection {
    std::string title;
    std::vector<std::string> header;
    std::vector<std::vector<std::string>> rows;
    std::vector<std::string> notes;  ///< paragraphs under the table
};

struct ReportData {
    std::string title;                 ///< page title
    std::string machine;               ///< machine name
    const MachineModel* machineModel = nullptr;  ///< needed to draw `maps` (axis kinds); may be null without maps
    std::vector<std::pair<std::string, std::string>> facts;  ///< shown in the page header (inputs, solver, …)
    std::vector<std::string> warnings;
    /// Shown first, as a red banner at the top of the page (verify: "COMPENSATION MAKES THE MACHINE WORSE …").
    std::vector<std::string> alarms;
    std::string afterNote;             ///< what "after" means in the runs' figures (shown under their table)
    std::vector<RunSection> runs;
    std::vector<TableSection> tables;  ///< shown after the runs
    std::vector<PassSpan> spans;       ///< verify: every pass of every run, ball bar and R-test
    std::vector<DeviationRow> deviations;
    std::vector<std::string> combinations;  ///< identifiable combinations of unidentified deviations, as text
    std::vector<MapPicture> maps;
    std::vector<ControllerSection> controllers;
};

}  // namespace cnccomp::app::report
