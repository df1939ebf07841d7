#include "postproc/interp_check.hpp"

#include "postproc/lexer.hpp"

namespace cnccomp::postproc {

GKind classifyG(int c, Dialect d) {
    const bool fanuc = d == Dialect::Fanuc, ngc = d == Dialect::Rs274ngc, siemens = d == Dialect::Sinumerik,
               printer = d == Dialect::Printer;
    if (siemens && (c == 740 || c == 750)) return GKind::Home;  // reference point / fixed point approach
    switch (c) {
        case 0: return GKind::Rapid;
        case 10: return GKind::Linear;
        case 20: return GKind::ArcCw;
        case 30: return GKind::ArcCcw;
        case 40: return GKind::Dwell;
        case 90: return GKind::Harmless;  // exact stop, non-modal
        case 170: return GKind::PlaneXY;
        case 180: return GKind::PlaneZX;
        case 190: return GKind::PlaneYZ;
        case 171: case 181: case 191: return ngc ? GKind::PlaneOther : GKind::Unknown;
        case 200: return GKind::Inch;
        case 210: return GKind::Metric;
        case 280: case 300: return GKind::Home;
        case 290: return GKind::Home;  // printer bed levelling / Fanuc return from the reference point
        case 281: case 301: return GKind::Harmless;
        case 310: return GKind::Skip;
        case 330: case 331: case 320: case 340: case 350: return GKind::OtherMotion;
        case 382: case 383: case 384: case 385: return GKind::OtherMotion;
        case 400: return GKind::CutterCompCancel;
        case 410: case 420: case 411: case 421: return GKind::CutterComp;
        case 430: return GKind::ToolLength;
        case 440: return fanuc ? GKind::ToolLengthNeg : GKind::Unknown;
        case 431: return ngc ? GKind::ToolLengthDynamic : GKind::Unknown;
        case 432: return ngc ? GKind::ToolLengthUnknown : GKind::Unknown;
        case 434: case 435: return GKind::Tcp;
        case 490: return GKind::ToolLengthCancel;
        case 520: return GKind::LocalOffset;
        case 530: return GKind::MachineCoords;
        case 531: return GKind::UnknownMotion;  // Fanuc: tool axis direction control (moves rotary axes)
        case 540: case 550: case 560: case 570: case 580: case 590: return GKind::WorkOffset;
        case 591: case 592: case 593: return ngc ? GKind::WorkOffset : GKind::Unknown;
        case 541: return fanuc ? GKind::WorkOffset : GKind::Unknown;
        case 610: case 611: case 640: case 600: case 601: case 602: case 603: case 641: case 642: case 643: case 644:
        case 645: return GKind::Harmless;
        case 650: return GKind::MacroCall;
        case 660: case 661: return GKind::ModalMacro;
        case 670: return GKind::ModalMacroCancel;
        case 680: case 681: case 682: return GKind::TransformOn;
        case 690: return GKind::TransformOff;
        case 800: return GKind::CycleCancel;
        case 730: case 740: case 760: case 810: case 820: case 830: case 840: case 841: case 842: case 850: case 860:
        case 870: case 880: case 890: return GKind::Cycle;
        case 900: return GKind::Absolute;
        case 910: return GKind::Incremental;
        case 901: return GKind::ArcAbsolute;
        case 911: return GKind::ArcIncremental;
        case 920: return GKind::PositionOffset;
        case 921: case 922: return GKind::PositionOffsetCancel;
        case 923: return GKind::PositionOffsetRestore;
        case 930: return GKind::FeedInverse;
        case 940: return GKind::FeedMinute;
        case 950: return GKind::FeedRev;
        case 960: case 970: return GKind::Harmless;  // constant surface speed on / off
        case 980: case 990: return GKind::Harmless;  // cycle return level (mill) / feed per minute, per rev (lathe)
        case 100: return printer ? GKind::Harmless : GKind::OffsetData;  // printers: firmware retract
        case 110: return printer ? GKind::Harmless : GKind::Unknown;
        default: break;
    }
    if (ngc) {
        if (c == 70) return GKind::Diameter;
        if (c == 80) return GKind::Radius;
        if (c == 50 || c == 51 || c == 52 || c == 53 || c == 120 || c == 130) return GKind::OtherMotion;  // splines, NURBS
        if (c == 700 || c == 710 || c == 720) return GKind::OtherMotion;  // lathe cycles
        if (c == 612) return GKind::Harmless;
    }
    if (fanuc) {
        if (c == 50 || c == 51 || c == 80 || c == 81) return GKind::Harmless;  // high-speed / look-ahead modes
        if (c == 500) return GKind::FanucG50;
        if (c == 510 || c == 511 || c == 160 || c == 121 || c == 1120) return GKind::TransformOn;
        if (c == 501 || c == 150 || c == 131 || c == 1130) return GKind::TransformOff;
        if (c == 71) return GKind::TransformToggle;  // G7.1 cylindrical interpolation: C radius, 0 = off
        if (c == 700 || c == 710 || c == 720 || c == 750 || c == 770 || c == 780 || c == 790) return GKind::OtherMotion;
    }
    if (siemens) {
        if (c == 700 || c == 7000) return GKind::Inch;
        if (c == 710 || c == 7100) return GKind::Metric;
        if (c == 5000 || (c >= 5050 && c <= 5990 && c % 10 == 0)) return GKind::WorkOffset;
        if (c == 1530) return GKind::MachineCoords;
        if (c == 250 || c == 260) return GKind::ConsumesAxes;  // spindle speed / working area limits
        if (c == 740 || c == 750) return GKind::Home;
        if (c == 1100 || c == 1110 || c == 1120) return GKind::TransformOn;  // polar coordinates
        if (c == 3310 || c == 3320) return GKind::OtherMotion;
        if (c == 6410 || c == 6420 || c == 6430 || c == 6440 || c == 6450 || c == 6010 || c == 6020 || c == 6030 ||
            c == 6200 || c == 6210 || c == 2900 || c == 2910)
            return GKind::Harmless;
    }
    if (printer) {
        if (c == 2900 || c == 260 || c == 270 || c == 600 || c == 610) return GKind::Harmless;
    }
    return GKind::Unknown;
}

WordCheck checkWords(const BlockWords& w, Dialect dialect) {
    WordCheck c;
    if (w.flow || (w.O && dialect == Dialect::Rs274ngc)) {
        c.refusal = {"program flow (o-word, loop, jump, condition or subroutine)", 0, false};
        return c;
    }
    if (w.unknownKeyword) {
        c.refusal = {"unknown keyword or call", 0, false};
        return c;
    }
    if (w.mCall || w.mSubEnd) {
        c.refusal = {w.mCall ? "subprogram call (M98/M97)" : "end of subprogram or jump (M99/M17)", 0, false};
        return c;
    }
    constexpr uint32_t kValueFlags = kExpression | kVariable | kAssignment | kMissingValue | kBadNumber | kExponent;
    if (w.flags & kNotEvaluable & ~kValueFlags) {
        c.refusal = {lexFlagReason(w.flags & kNotEvaluable & ~kValueFlags), 0, true};
        return c;
    }
    // A value the lexer could not read: the block's modal codes still count, its motion is not evaluated (the reason
    // is given first; a refusal below keeps it).
    if (w.flags & kValueFlags) c.onlyModalReason = lexFlagReason(w.flags & kValueFlags);
    if (w.gProblem) {
        c.refusal = {"G word that is not a plain G code", 0, true};
        return c;
    }
    if (w.duplicateAxis) c.refusal = {"the same axis twice in one block", 0, false};
    return c;
}

Refusal checkGCodes(const BlockWords& w, Dialect dialect, GCodes& g) {
    g.count = w.nG;
    for (int k = 0; k < w.nG; ++k) {
        const GKind kind = classifyG(w.gCode[k], dialect);
        g.kind[k] = kind;
        g.mask |= uint64_t{1} << static_cast<int>(kind);
        if (kind == GKind::Unknown) return {"G code not supported", w.gCode[k], true};
        // G80 next to G0/G1 (common in program headers) cancels the cycle first: not a second motion code.
        const bool isMotion = kind == GKind::Rapid || kind == GKind::Linear || kind == GKind::ArcCw ||
                              kind == GKind::ArcCcw || kind == GKind::OtherMotion || kind == GKind::Cycle ||
                              kind == GKind::UnknownMotion;
        const bool isNonModal = kind == GKind::Dwell || kind == GKind::Home || kind == GKind::MachineCoords ||
                                kind == GKind::OffsetData || kind == GKind::PositionOffset ||
                                kind == GKind::LocalOffset || kind == GKind::FanucG50 || kind == GKind::MacroCall ||
                                kind == GKind::Skip || kind == GKind::ConsumesAxes || kind == GKind::TransformToggle ||
                                kind == GKind::ToolLengthDynamic || kind == GKind::ModalMacro;
        if (isMotion) {
            if (g.motionIndex >= 0) return {"two motion codes in one block", 0, false};
            g.motionIndex = k;
        }
        if (isNonModal) {
            if (g.nonModalIndex >= 0) return {"two non-modal codes in one block", 0, false};
            g.nonModalIndex = k;
        }
    }
    g.nonModal = g.nonModalIndex >= 0 ? g.kind[g.nonModalIndex] : GKind::Harmless;
    if (g.nonModal == GKind::MacroCall) return {"macro call (G65)", 0, false};
    return {};
}

}  // namespace cnccomp::postproc
