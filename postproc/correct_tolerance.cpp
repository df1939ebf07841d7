// What a corrected move must hold, shared by the RS274NGC-family and the Klartext correctors: the path tolerance the
// written digits allow, and the refusal of a rotary move whose correction depends on a tool length nobody gave.
#include <algorithm>
#include <cmath>
#include <cstdint>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/number_format.hpp"
#include "postproc/correct_program.hpp"

namespace cnccomp::postproc {
using namespace cnccomp::io;

double digitsTolerance(Corrector& corrector, const MoveSpace& space, const AxisVector& end, int linDecimals,
                       int rotDecimals, bool inch, int linearAxes, int rotaryAxes) {
    const double linStep = tenTo(-linDecimals) * (inch ? 25.4 : 1.0);
    double floor = 0.5 * linStep * std::sqrt(static_cast<double>(std::max(linearAxes, 1)));
    if (space.mode == ProgramMode::Joints && rotaryAxes > 0) {
        // Lever arm of the rotary axes at this pose: the tip's distance from the workpiece origin plus the tool.
        const double lever = corrector.nominalTip(end, space.toolLength).norm() + std::fabs(space.toolLength);
        floor += 0.5 * tenTo(-rotDecimals) * kDeg * lever * std::sqrt(static_cast<double>(rotaryAxes));
    }
    return floor;
}

double toleranceWithin(double tolMm, double floorMm, int linDecimals, CorrectSummary& summary, std::ostream* report,
                       uint64_t line, bool& warned) {
    if (tolMm >= floorMm) return tolMm;
    ++summary.clampedTolerance;
    summary.toleranceFloor = std::max(summary.toleranceFloor, floorMm);
    if (!warned) {
        warned = true;
        addNotice(summary, report, true, line,
                  fmt::format("--tol-um {:.3g} is below what the written digits can hold here ({:.3g} um with {} "
                              "decimals): moves are checked against {:.3g} um (--decimals writes more digits)",
                              tolMm / kUm, floorMm / kUm, linDecimals, floorMm / kUm));
    }
    return floorMm;
}

void refuseAssumedToolLength(Corrector& corrector, const AxisLayout& layout, const AxisVector& cNom,
                             const AxisVector& cEnd, double toolLength, double toleranceMm, const std::string& name,
                             uint64_t line) {
    bool rotaryOff = false;
    for (int a = 0; a < layout.count; ++a)
        if (layout.rotary[a] && std::fabs(cNom[a]) > 1e-9) rotaryOff = true;
    if (!rotaryOff) return;
    const double off = corrector.tipDeviation(cNom, cEnd, toolLength + kToolLengthProbeMm);
    if (!(off > toleranceMm)) return;
    throw InputError(name, static_cast<int>(std::min<uint64_t>(line, INT32_MAX)),
                     fmt::format("the correction of this rotary move depends on the tool length, which was not given: "
                                 "corrected for a tool point at {:g} mm, it leaves a point {:g} mm further along the tool "
                                 "{:.1f} um off its path; give the length the program was made for with --tool-length L "
                                 "(--tool-length 0 when 0 is meant; G43 Hn: --tool-length Hn=L or --tool-table)",
                                 toolLength, kToolLengthProbeMm, off / kUm));
}

}  // namespace cnccomp::postproc
