#include "postproc/correct_move.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace cnccomp::postproc {

EndPointSolver::Result EndPointSolver::solve(Corrector& corrector, const AxisLayout& layout, const CorrectOptions& options,
                                             double toolLength, const AxisVector& cNom, const NominalPose* nomPose,
                                             const ToolLengthCheck& check, AxisVector& cEnd) {
    // Near the previous end point's correction (warm start and continuity) and the programmed value.
    AxisVector start;
    if (haveDelta_) corrector.predictStart(cNom, lastCNom_, lastDelta_, toolLength, start);
    else start = cNom + lastDelta_;
    const SolveResult s =
        corrector.solve(cNom, toolLength, start, cEnd, haveDelta_ ? &lastDelta_ : nullptr, Vec3::Zero(), nomPose);
    Result r;
    r.tipResidual = s.tipError;
    r.axisResidual = s.axisError;
    if (!s.converged || !(s.tipError < 1e-5)) {
        r.unconverged = true;
        r.failure = fmt::format("the correction did not converge (tip residual {:.3g} um); end point left uncorrected",
                                s.tipError / kUm);
        cEnd = cNom;
        return r;
    }
    if (check.assumed && options.requireToolLength)
        refuseAssumedToolLength(corrector, layout, cNom, cEnd, toolLength, options.corrector.toleranceMm, options.inputName,
                                check.line);
    lastDelta_ = cEnd - cNom;
    lastCNom_ = cNom;
    haveDelta_ = true;
    r.corrected = true;
    return r;
}

TravelCheck::TravelCheck(const MachineModel& m, const AxisLayout& layout) : layout_(layout) {
    for (int a = 0; a < layout.count; ++a) {
        const Link& link = m.axisLink(a);
        min_[a] = link.min - link.machineZero;
        max_[a] = link.max - link.machineZero;
    }
}

std::string TravelCheck::message(int a, double value, bool asProgrammed) const {
    const double k = layout_.rotary[a] ? 1.0 / kDeg : 1.0;
    const char* unit = layout_.rotary[a] ? "deg" : "mm";
    return fmt::format("axis {} at {:.4f} {} ({}) is outside its travel [{:g}, {:g}] {}: corrected all the same",
                       layout_.letter[a], value * k, unit, asProgrammed ? "as programmed" : "after correction",
                       min_[a] * k, max_[a] * k, unit);
}

void countCorrection(CorrectSummary& summary, const AxisLayout& layout, const AxisVector& cNom, const AxisVector& cEnd,
                     uint64_t line) {
    for (int a = 0; a < layout.count; ++a) {
        const double d = std::fabs(cEnd[a] - cNom[a]);
        if (layout.rotary[a]) {
            if (d > summary.maxRotaryCorrection) summary.maxRotaryCorrection = d, summary.maxRotaryLine = line;
        } else if (d > summary.maxLinearCorrection) {
            summary.maxLinearCorrection = d, summary.maxLinearLine = line;
        }
    }
}

void blendStartOffset(Corrector& corrector, const ProgramPoint& nomStart, double toleranceMm, PathContext& ctx,
                      CorrectSummary& summary) {
    AxisVector c0, cOut;
    if (!corrector.toJoints(ctx.space, nomStart, ctx.guess, c0) || !corrector.toJoints(ctx.space, ctx.outStart, ctx.guess, cOut))
        return;
    ctx.startOffset = corrector.actualTip(cOut, ctx.space.toolLength) - corrector.nominalTip(c0, ctx.space.toolLength);
    if (ctx.startOffset.norm() > toleranceMm) ++summary.offPathStarts;
}

void countPath(const SplitStats& stats, CorrectSummary& summary, std::ostream* report, uint64_t line) {
    summary.maxPathDeviation = std::max(summary.maxPathDeviation, stats.maxDeviation);
    if (stats.bounded) ++summary.boundedChecks;
    if (!stats.limited) return;
    ++summary.limited;
    addNotice(summary, report, true, line,
              fmt::format("tolerance not met after the subdivision limit ({:.3f} um left)", stats.maxDeviation / kUm));
}

}  // namespace cnccomp::postproc
