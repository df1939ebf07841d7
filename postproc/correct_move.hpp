#pragma once
// One correction core for every dialect: what both correctors do with a move once they have read it. The
// RS274NGC-family corrector (postproc/correct_front_end + correct_back_end) and the HEIDENHAIN Klartext corrector
// (postproc/klartext_correct) only read their dialect and write their words; the end point solved from the previous
// one's correction, the travel check, the start-offset blend, and the summary's counts are the same code here.
#include <cstdint>
#include <string>

#include "cnccomp/machine.hpp"
#include "postproc/correct_program.hpp"
#include "postproc/correction.hpp"
#include "postproc/modal.hpp"

namespace cnccomp::postproc {

/// The end points of a program's moves, each solved from the previous end point's correction: warm start and
/// continuity (Corrector::predictStart from the second move on).
class EndPointSolver {
public:
    explicit EndPointSolver(int axisCount) : lastDelta_(AxisVector::Zero(axisCount)), lastCNom_(lastDelta_) {}

    struct Result {
        double tipResidual = 0;  ///< mm
        double axisResidual = 0; ///< rad
        bool corrected = false;  ///< converged: cEnd is the correction, and the next end point starts from it
        bool unconverged = false;///< cEnd = cNom; `failure` says why (a warning)
        std::string failure;
    };
    /// A tool length nobody gave (BlockResult::tipLengthAssumed) is refused where the correction depends on it
    /// (refuseAssumedToolLength; `options.requireToolLength`), naming `options.inputName`:`line`.
    struct ToolLengthCheck {
        bool assumed = false;
        uint64_t line = 0;
    };

    /// `cEnd`: the commands at which the erroneous machine puts the tool where the nominal one puts it at `cNom`
    /// (`nomPose`: that pose when the caller has it from Corrector::toJoints). Not converged to 1e-5 mm: cEnd = cNom
    /// and the continuity is kept from the last converged end point.
    Result solve(Corrector& corrector, const AxisLayout& layout, const CorrectOptions& options, double toolLength,
                 const AxisVector& cNom, const NominalPose* nomPose, const ToolLengthCheck& check, AxisVector& cEnd);

private:
    AxisVector lastDelta_, lastCNom_;
    bool haveDelta_ = false;  ///< lastDelta_ is the correction at the previous end point (continuity)
};

/// Each axis' travel in the controller's machine coordinates (link min/max less the machine zero).
class TravelCheck {
public:
    TravelCheck(const MachineModel& m, const AxisLayout& layout);
    /// Calls note(message) for every axis whose nominal (`cNom`) or corrected (`c`) position is outside its travel;
    /// true when one is.
    template <class Note>
    bool check(const AxisVector& cNom, const AxisVector& c, Note&& note) const {
        bool outside = false;
        for (int a = 0; a < layout_.count; ++a) {
            const bool nomOut = cNom[a] < min_[a] - 1e-9 || cNom[a] > max_[a] + 1e-9;
            const bool corOut = c[a] < min_[a] - 1e-9 || c[a] > max_[a] + 1e-9;
            if (!nomOut && !corOut) continue;
            outside = true;
            note(message(a, nomOut ? cNom[a] : c[a], nomOut));
        }
        return outside;
    }

private:
    std::string message(int a, double value, bool asProgrammed) const;
    AxisLayout layout_;
    double min_[kMaxAxes] = {}, max_[kMaxAxes] = {};
};

/// The largest linear and rotary corrections of the summary (and their lines), with this end point's.
void countCorrection(CorrectSummary& summary, const AxisLayout& layout, const AxisVector& cNom, const AxisVector& cEnd,
                     uint64_t line);

/// ctx.startOffset where the output starts off the corrected nominal start `nomStart` (a block before was passed
/// through, or TCP was just switched on): splitting cannot remove that offset, so it is blended out along the move,
/// not measured. Counted in summary.offPathStarts when above `toleranceMm`.
void blendStartOffset(Corrector& corrector, const ProgramPoint& nomStart, double toleranceMm, PathContext& ctx,
                      CorrectSummary& summary);

/// A move's path check into the summary: its largest deviation, and a warning at `line` when the subdivision limit
/// left the tolerance unmet.
void countPath(const SplitStats& stats, CorrectSummary& summary, std::ostream* report, uint64_t line);

}  // namespace cnccomp::postproc
