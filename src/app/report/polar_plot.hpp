#pragma once
// Polar plot of a ball-bar run in the style of ball-bar software: the nominal circle (radius LB) drawn at a fixed
// size, the radial deviation ΔL magnified around it, scale rings every `ringUm` µm, the CCW and CW passes and the
// traces before and after compensation overlaid in four colours (CW wide underneath, CCW narrow on top), ISO 230-4
// figures underneath.
#include <string>

#include "app/report/report_data.hpp"

namespace cnccomp::app::report {

/// Trace colours (also what the browser test looks for in a screenshot).
inline constexpr const char* kCcwBefore = "#1f4fd8";
inline constexpr const char* kCwBefore = "#d62728";
inline constexpr const char* kCcwAfter = "#17a34a";
inline constexpr const char* kCwAfter = "#f08c00";

/// Size of the picture and where the nominal circle sits (px).
inline constexpr double kPolarWidth = 600, kPolarHeight = 720, kPolarCx = 300, kPolarCy = 340;
inline constexpr double kPolarNominalPx = 150;  ///< radius of the nominal circle
inline constexpr double kPolarBandPx = 100;     ///< the outermost scale ring is this far from the nominal circle
/// Line widths: CW drawn wide underneath, CCW narrow on top, so that passes without hysteresis show both colours.
inline constexpr double kPolarCwWidthPx = 4, kPolarCcwWidthPx = 1.8;

/// Magnification of a run: ring spacing (a round number of µm), ring count on each side, px per µm.
struct PolarScale {
    double ringUm = 1;
    int rings = 1;
    double pxPerUm = 100;
};
/// From the largest |ΔL| of every pass, before and after (at least 0.1 µm full scale).
PolarScale polarScale(const RunSection& run);

/// Pixel position of a sample (x right, y down).
struct PolarPixel {
    double x, y;
};
PolarPixel polarPixel(const PolarScale& s, double angleDeg, double dL);

/// The SVG (no XML prolog, so that it can also be put inline in HTML); ids start with `idPrefix`.
std::string renderPolarPlot(const RunSection& run, const std::string& idPrefix = "polar");

}  // namespace cnccomp::app::report
