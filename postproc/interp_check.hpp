#pragma once
// The interpreter's second step: decide from what a block says (postproc/interp_read.hpp) whether it can be
// evaluated at all, before any modal state changes (LinuxCNC src/emc/rs274ngc/interp_check.cc: check_items /
// check_g_codes refuse a block with two codes of one modal group, axis words with G80, …). Here a refusal does not stop
// the program: the block is passed through unchanged and what it makes unknown is said (postproc/modal.hpp, BlockKind).
// Also the classification of G codes per dialect (LinuxCNC's gees[] table of modal groups, interp_array.cc).
#include <array>
#include <cstdint>

#include "postproc/dialect.hpp"
#include "postproc/interp_read.hpp"

namespace cnccomp::postproc {

/// What a G code does, as far as following positions is concerned.
enum class GKind : uint8_t {
    Rapid, Linear, ArcCw, ArcCcw, OtherMotion, Cycle, CycleCancel,
    PlaneXY, PlaneZX, PlaneYZ, PlaneOther,
    Inch, Metric, Absolute, Incremental, ArcAbsolute, ArcIncremental,
    FeedInverse, FeedMinute, FeedRev,
    ToolLength, ToolLengthNeg, ToolLengthDynamic, ToolLengthUnknown, ToolLengthCancel, Tcp,
    WorkOffset, Dwell, Home, MachineCoords, OffsetData, PositionOffset, PositionOffsetCancel, PositionOffsetRestore,
    LocalOffset, FanucG50, TransformOn, TransformOff, TransformToggle, MacroCall, ModalMacro, ModalMacroCancel,
    Skip, ConsumesAxes, Diameter, Radius, CutterComp, CutterCompCancel, UnknownMotion, Harmless, Unknown
};
static_assert(static_cast<int>(GKind::Unknown) < 64, "GCodes::mask holds one bit per GKind");

/// Kind of G code `code` (G × 10) in `dialect`; Unknown when it is not supported.
GKind classifyG(int code, Dialect dialect);

/// A block's G codes, classified.
struct GCodes {
    std::array<GKind, 16> kind{};
    int count = 0;
    uint64_t mask = 0;        ///< one bit per GKind present
    int motionIndex = -1;     ///< index of the motion code (G0 … G3, cycles, other motions), -1 none
    int nonModalIndex = -1;   ///< index of the non-modal code (G4, G10, G28, G53, G92 …), -1 none
    GKind nonModal = GKind::Harmless;  ///< its kind, Harmless when none

    bool has(GKind g) const { return (mask >> static_cast<int>(g)) & 1u; }
    /// Index of the first code of kind g, -1 none.
    int index(GKind g) const {
        for (int k = 0; k < count; ++k)
            if (kind[k] == g) return k;
        return -1;
    }
};

/// Why a block is not evaluated, and whether its motion mode becomes unknown too (its positions always do).
struct Refusal {
    const char* reason = nullptr;  ///< static string; nullptr: no refusal
    int code = 0;                  ///< G code × 10 concerned, or 0
    bool forgetMotion = false;
    explicit operator bool() const { return reason != nullptr; }
};

/// The checks on the words alone: control flow, unknown keywords, subprogram calls, what the lexer could not read,
/// G words that are not plain codes, an axis twice. A block whose only problem is a value the lexer could not read
/// (expression, variable …) keeps its modal codes: `onlyModalReason` says why its motion is not evaluated.
struct WordCheck {
    Refusal refusal;
    const char* onlyModalReason = nullptr;
};
WordCheck checkWords(const BlockWords& w, Dialect dialect);

/// Classifies the block's G codes into `g` and refuses unsupported codes, two motion codes, two non-modal codes
/// (G80 beside G0/G1 is a cancel, not a second motion) and G65 macro calls.
Refusal checkGCodes(const BlockWords& w, Dialect dialect, GCodes& g);

}  // namespace cnccomp::postproc
