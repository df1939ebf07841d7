// The summary of `cnccomp correct` (both correctors): its notices, and its text for the terminal.
#include <algorithm>
#include <ostream>

#include <fmt/format.h>

#include "postproc/correct_program.hpp"
#include "postproc/block_writer.hpp"
#include "postproc/line_reader.hpp"

namespace cnccomp::postproc {

void finishCorrection(OutputBuffer& out, const LineReader& reader, const CorrectOptions& options, CorrectSummary& s) {
    out.flush();
    if (options.progress) options.progress(reader.bytesConsumed());
    s.bytesIn = reader.bytesConsumed();
    s.bytesOut = out.bytesWritten();
}

void addNotice(CorrectSummary& summary, std::ostream* report, bool warning, uint64_t line, std::string message) {
    auto& list = warning ? summary.warnings : summary.passThrough;
    if (warning) ++summary.warningCount;
    if (report) {
        // Plain CSV without quoting (as every CSV of the project): commas in messages become semicolons.
        std::string m = message;
        std::replace(m.begin(), m.end(), ',', ';');
        *report << line << ',' << (warning ? "warning" : "pass-through") << ',' << m << '\n';
    }
    if (list.size() < CorrectSummary::kMaxNotices) list.push_back({line, std::move(message)});
}

std::string formatSummary(const CorrectSummary& s, size_t maxListed) {
    std::string t;
    t += fmt::format("dialect: {}{}\n", dialectName(s.dialect),
                     s.dialectDetected ? fmt::format(" (detected: {}{})", s.dialectReason,
                                                     s.dialectCertain ? "" : "; use --dialect to choose")
                                       : std::string());
    t += fmt::format("blocks read: {} ({} lines, {} bytes in, {} bytes out)\n", s.blocks, s.lines, s.bytesIn, s.bytesOut);
    t += fmt::format("moves evaluated: {}; blocks corrected: {}; moves split: {} (+{} lines, {} arcs into lines)\n",
                     s.moves, s.corrected, s.split, s.addedLines, s.arcsToLines);
    t += fmt::format("passed through unchanged: {} ({} of them ordinary uncorrected moves: G53, reference returns)\n",
                     s.passedThrough, s.notCorrected);
    t += fmt::format("largest correction: {:.3f} um linear (line {}), {:.3f} arcsec rotary (line {})\n",
                     s.maxLinearCorrection / kUm, s.maxLinearLine, s.maxRotaryCorrection / kArcsec, s.maxRotaryLine);
    t += fmt::format("largest residual: {:.2g} um at endpoints, {:.3f} um on the path (checked midpoints), tool axis {:.3f} arcsec\n",
                     s.maxTipResidual / kUm, s.maxPathDeviation / kUm, s.maxAxisResidual / kArcsec);
    if (s.headerToolLengthLine)
        t += fmt::format("tool length: {:g} mm, from the program's header (line {}: cnccomp correct --tool-length {:g})\n",
                         s.headerToolLength, s.headerToolLengthLine, s.headerToolLength);
    if (s.tcpMoves) t += fmt::format("moves in tool-tip (TCP) mode: {}\n", s.tcpMoves);
    if (s.unconverged) t += fmt::format("endpoints not converged (left unchanged): {}\n", s.unconverged);
    if (s.limited) t += fmt::format("moves over the tolerance after the subdivision limit: {}\n", s.limited);
    if (s.outsideTravel) t += fmt::format("moves outside the travel of an axis: {} (see the warnings)\n", s.outsideTravel);
    if (s.clampedTolerance)
        t += fmt::format("tolerance raised to {:.3g} um on {} moves: the written digits cannot hold less\n",
                         s.toleranceFloor / kUm, s.clampedTolerance);
    if (s.offPathStarts)
        t += fmt::format("moves starting off the nominal path after a block passed through: {} (offset blended out, "
                         "not split for)\n",
                         s.offPathStarts);
    if (!s.passThrough.empty()) {
        t += "not evaluated (passed through):\n";
        for (size_t i = 0; i < s.passThrough.size() && i < maxListed; ++i)
            t += fmt::format("  line {}: {}\n", s.passThrough[i].line, s.passThrough[i].message);
        const uint64_t listed = std::min<uint64_t>(s.passThrough.size(), maxListed);
        const uint64_t reported = s.passedThrough - s.notCorrected;
        if (reported > listed) t += fmt::format("  … and {} more (--report FILE lists all)\n", reported - listed);
    }
    if (!s.warnings.empty()) {
        t += "warnings:\n";
        for (size_t i = 0; i < s.warnings.size() && i < maxListed; ++i)
            t += fmt::format("  line {}: {}\n", s.warnings[i].line, s.warnings[i].message);
        if (s.warningCount > std::min<uint64_t>(s.warnings.size(), maxListed))
            t += fmt::format("  … and {} more\n", s.warningCount - std::min<uint64_t>(s.warnings.size(), maxListed));
    }
    return t;
}

}  // namespace cnccomp::postproc
