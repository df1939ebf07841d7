// The interpreter's third step: apply a checked block to the modal state and the position, in the RS274NGC order of
// execution (LinuxCNC src/emc/rs274ngc/interp_convert.cc, execute_block: feed mode, feed, tool, plane, units, cutter
// compensation, tool length, work offset, distance modes, non-modal codes, motion; the order is listed in LinuxCNC's
// G-code overview, docs/src/gcode/overview.adoc, "Order of Execution"). Members of Interpreter
// (postproc/modal.hpp); the driver is Interpreter::interpret (postproc/interpreter.cpp).
#include <cmath>

#include "postproc/interp_check.hpp"
#include "postproc/modal.hpp"

namespace cnccomp::postproc {

void Interpreter::refuse(BlockResult& r, const Refusal& why) {
    passThrough(r, why.reason, why.code);
    unknownAll(r);
    if (why.forgetMotion) motion_ = Motion::Unknown;
}

void Interpreter::convertFeedPlaneUnits(const BlockWords& w, const GCodes& g, BlockResult& r) {
    if (g.has(GKind::FeedInverse)) feedMode_ = FeedMode::InverseTime;
    if (g.has(GKind::FeedMinute)) feedMode_ = FeedMode::PerMinute;
    if (g.has(GKind::FeedRev)) feedMode_ = FeedMode::PerRevolution;
    if (w.F && w.F->kind == ValueKind::Number) feed_ = w.F->value;
    if (w.T && w.T->kind == ValueKind::Number && w.T->value >= 0 && w.T->value < 1e6) tool_ = static_cast<int>(w.T->value);
    if (g.has(GKind::PlaneXY)) plane_ = 17;
    if (g.has(GKind::PlaneZX)) plane_ = 18;
    if (g.has(GKind::PlaneYZ)) plane_ = 19;
    if (g.has(GKind::PlaneOther)) plane_ = 0;
    if (g.has(GKind::Inch)) inch_ = true, unitsSet_ = true;
    if (g.has(GKind::Metric)) inch_ = false, unitsSet_ = true;
    if (g.has(GKind::CutterComp)) {
        if (!cutterComp_) warn(r, Warning::CutterCompensation, 0);
        cutterComp_ = true;
    }
    if (g.has(GKind::CutterCompCancel)) cutterComp_ = false;
}

void Interpreter::convertToolLength(const BlockWords& w, const GCodes& g, const LexedBlock& b, BlockResult& r) {
    if (g.has(GKind::ToolLength) || g.has(GKind::ToolLengthNeg) || g.has(GKind::Tcp)) {
        int number = tool_;
        if (w.H && w.H->kind == ValueKind::Number && w.H->value >= 0 && w.H->value < 1e6)
            number = static_cast<int>(w.H->value);
        const auto len = options_.setup.toolLength(number);
        if (!len) warn(r, Warning::ToolLengthNotGiven, number);
        tloLength_ = len ? *len : options_.setup.defaultToolLength;
        tloAssumed_ = !len && !options_.setup.defaultToolLengthGiven;
        tloSign_ = g.has(GKind::ToolLengthNeg) ? -1 : 1;
        tloKnown_ = true;
        if (layout_.zAxis < 0) warn(r, Warning::NoToolLengthAxis, 0);
        if (const int k = g.index(GKind::Tcp); k >= 0) {
            // Fanuc tool centre point control: G43.4 type 1 (rotary angles), G43.5 type 2 (I J K vector).
            mode_ = w.gCode[k] == 435 ? ProgramMode::TcpVector : ProgramMode::TcpAngles;
            tcpSource_ = w.gCode[k] == 435 ? TcpSource::FanucVector : TcpSource::FanucAngles;
        }
    }
    if (g.nonModal == GKind::ToolLengthDynamic) {
        const int z = layout_.zAxis;
        if (z >= 0 && r.axisWord[z] >= 0 && b.words[r.axisWord[z]].kind == ValueKind::Number) {
            tloLength_ = wordValue(b.words[r.axisWord[z]]) * (inch_ ? 25.4 : 1.0);
            tloSign_ = 1;
            tloKnown_ = true;
            tloAssumed_ = false;  // G43.1 Z…: the program gives the length
        } else {
            tloKnown_ = false;
        }
    }
    if (g.has(GKind::ToolLengthUnknown)) tloKnown_ = false;
    if (g.has(GKind::ToolLengthCancel)) {
        tloSign_ = 0;
        tloLength_ = 0;
        tloKnown_ = true;
        tloAssumed_ = false;
        if (tcpSource_ == TcpSource::FanucAngles || tcpSource_ == TcpSource::FanucVector) {
            mode_ = ProgramMode::Joints;
            tcpSource_ = TcpSource::None;
        }
    }
}

Refusal Interpreter::convertWorkOffset(const BlockWords& w, const GCodes& g) {
    const int k = g.index(GKind::WorkOffset);
    if (k < 0) return {};
    int p = 0;
    if (w.gCode[k] == 541) {
        if (!w.P || w.P->kind != ValueKind::Number || w.P->value < 1 || w.P->value > 300)
            return {"G54.1 without a valid P number", 541, false};
        p = static_cast<int>(w.P->value);
    }
    offsetCode_ = offsetCodeOfG(w.gCode[k] / 10.0, p);
    return {};
}

void Interpreter::convertModes(const BlockWords& w, const GCodes& g, const LexedBlock& b, BlockResult& r,
                               ProgramMode modeBefore) {
    // Distance modes, lathe diameter mode, transformations, modal macros.
    if (g.has(GKind::Absolute)) absolute_ = true;
    if (g.has(GKind::Incremental)) absolute_ = false;
    if (g.has(GKind::ArcAbsolute)) arcAbsolute_ = true;
    if (g.has(GKind::ArcIncremental)) arcAbsolute_ = false;
    if (g.has(GKind::Diameter) || w.diameterKeyword == 1) diameter_ = true;
    if (g.has(GKind::Radius) || w.diameterKeyword == 0) diameter_ = false;
    if (g.has(GKind::TransformOn) || w.transformOn) transform_ = true;
    if (g.has(GKind::TransformOff)) transform_ = false;
    if (g.nonModal == GKind::TransformToggle) {
        bool on = false;
        for (int a = 0; a < layout_.count; ++a)
            if (r.axisWord[a] >= 0 && b.words[r.axisWord[a]].value != 0) on = true;
        transform_ = on;
    }
    if (g.nonModal == GKind::ModalMacro) modalMacro_ = true;
    if (g.has(GKind::ModalMacroCancel)) modalMacro_ = false;
    // Sinumerik TCP keywords.
    if (w.tcpOn) {
        mode_ = ProgramMode::TcpAngles;
        tcpSource_ = TcpSource::Sinumerik;
    }
    if (w.tcpOff) {
        mode_ = ProgramMode::Joints;
        tcpSource_ = TcpSource::None;
        transform_ = false;
    }
    // A user-declared switch (--tcp-on M428 --tcp-off M429: LinuxCNC's switchable trt kinematics, whose remapped M
    // codes run before the block's motion, modal group 10).
    if (w.userTcpOn) {
        mode_ = ProgramMode::TcpAngles;
        tcpSource_ = TcpSource::UserSwitch;
    }
    if (w.userTcpOff && tcpSource_ == TcpSource::UserSwitch) {
        mode_ = ProgramMode::Joints;
        tcpSource_ = TcpSource::None;
    }
    if (mode_ != modeBefore) r.modeSwitch = true;
    if (g.has(GKind::PositionOffsetCancel)) g92Unknown_ = 0;
    if (g.has(GKind::PositionOffsetRestore)) g92Unknown_ = layout_.all();
}

Refusal Interpreter::convertMotionMode(const BlockWords& w, const GCodes& g, BlockResult& r) {
    const Dialect dialect = options_.dialect;
    if (g.has(GKind::CycleCancel)) {
        if (dialect == Dialect::Rs274ngc && g.motionIndex < 0) motion_ = Motion::Unknown;
        cycleActive_ = false;
        if (motion_ == Motion::Cycle) motion_ = Motion::Unknown;
    }
    if (g.motionIndex < 0) return {};
    r.motionWord = w.gWord[g.motionIndex];
    r.motionCode = true;
    switch (g.kind[g.motionIndex]) {
        case GKind::Rapid: motion_ = Motion::Rapid; cycleActive_ = false; break;
        case GKind::Linear: motion_ = Motion::Linear; cycleActive_ = false; break;
        case GKind::ArcCw: motion_ = Motion::ArcCw; cycleActive_ = false; break;
        case GKind::ArcCcw: motion_ = Motion::ArcCcw; cycleActive_ = false; break;
        case GKind::OtherMotion: motion_ = Motion::Other; cycleActive_ = false; break;
        case GKind::Cycle:
            if (dialect == Dialect::Rs274ngc) motion_ = Motion::Cycle;
            else cycleActive_ = true;
            break;
        case GKind::UnknownMotion: return {"tool axis control (G53.1)", 0, false};
        default: break;
    }
    return {};
}

Refusal Interpreter::convertModalCodes(const BlockWords& w, const GCodes& g, const LexedBlock& b, BlockResult& r,
                                       ProgramMode modeBefore) {
    convertFeedPlaneUnits(w, g, r);
    convertToolLength(w, g, b, r);
    if (const Refusal why = convertWorkOffset(w, g)) return why;
    convertModes(w, g, b, r, modeBefore);
    return convertMotionMode(w, g, r);
}

void Interpreter::convertOffsetData(const BlockWords& w, const LexedBlock& b, BlockResult& r) {
    const Dialect dialect = options_.dialect;
    const int l = w.L && w.L->kind == ValueKind::Number ? static_cast<int>(w.L->value) : -1;
    const int p = w.P && w.P->kind == ValueKind::Number ? static_cast<int>(w.P->value) : -1;
    if (l != 2 && l != 20) return;  // tool tables and other data: no effect on positions
    int code = -1;
    if (p == 0 && dialect != Dialect::Fanuc) code = offsetCode_;
    else if (p >= 1 && p <= 6) code = 540 + 10 * (p - 1);
    else if (p >= 7 && p <= 9 && dialect == Dialect::Rs274ngc) code = 591 + (p - 7);
    if (code < 0) {
        passThrough(r, "G10 for an offset that cannot be followed", 100);
        return;
    }
    if (l == 20) {
        bool found = false;
        for (auto& [c, m] : offsetsUnknown_)
            if (c == code) {
                m |= r.words;
                found = true;
            }
        if (!found) offsetsUnknown_.emplace_back(code, r.words);
        passThrough(r, "G10 L20 offset depends on the actual position", 100);
        return;
    }
    AxisVector* target = nullptr;
    for (auto& [c, v] : offsets_)
        if (c == code) target = &v;
    if (!target) {
        offsets_.emplace_back(code, AxisVector::Zero(layout_.count));
        target = &offsets_.back().second;
    }
    for (int a = 0; a < layout_.count; ++a) {
        if (r.axisWord[a] < 0) continue;
        const Word& word = b.words[r.axisWord[a]];
        if (word.kind != ValueKind::Number) continue;
        const double v = wordValue(word) * (layout_.rotary[a] ? kDeg : (inch_ ? 25.4 : 1.0));
        (*target)[a] = (dialect == Dialect::Fanuc && !absolute_) ? (*target)[a] + v : v;
    }
    for (auto& [c, m] : offsetsUnknown_)
        if (c == code) m &= ~r.words;
}

bool Interpreter::convertNonModal(const BlockWords& w, const GCodes& g, const LexedBlock& b, BlockResult& r) {
    switch (g.nonModal) {
        case GKind::Dwell:
        case GKind::ConsumesAxes:
        case GKind::ToolLengthDynamic:
        case GKind::TransformToggle:
        case GKind::ModalMacro:
            return true;
        case GKind::OffsetData:
            convertOffsetData(w, b, r);
            return true;
        case GKind::LocalOffset:
            for (int a = 0; a < layout_.count; ++a) {
                if (r.axisWord[a] < 0) continue;
                const Word& word = b.words[r.axisWord[a]];
                if (word.kind != ValueKind::Number) continue;
                local_[a] = wordValue(word) * (layout_.rotary[a] ? kDeg : (inch_ ? 25.4 : 1.0));
            }
            fillConversions(r);
            return true;
        case GKind::Home: {
            // Without axis words every axis homes, except rotary axes the program never commands (still taken at 0).
            const AxisMask mask = r.words ? r.words : (layout_.all() & ~assumed_);
            passThrough(r, "reference point return (position afterwards unknown)", w.gCode[g.nonModalIndex], false);
            known_ &= ~mask;
            assumed_ &= ~mask;
            r.endKnown = known_;
            return true;
        }
        case GKind::PositionOffset:
        case GKind::FanucG50:
            if (r.words == 0) {
                if (g.nonModal == GKind::FanucG50) transform_ = false;  // G50 without axes: scaling off / spindle clamp
                return true;
            }
            g92Unknown_ |= r.words;
            passThrough(r, "coordinate offset set from the actual position (G92 / G50)", w.gCode[g.nonModalIndex]);
            return true;
        case GKind::Skip:
            passThrough(r, "skip move (G31)", 310);
            known_ &= ~r.words;
            r.endKnown = known_;
            return true;
        default:
            return false;  // G53 (machine coordinates) and blocks without a non-modal code: their motion follows
    }
}

Refusal Interpreter::convertToolVector(const BlockWords& w, const LexedBlock& b, BlockResult& r) {
    if (w.extProblem)
        return {"address with an extension other than A3= B3= C3= (e.g. Euler angles A2=): not supported", 0, false};
    if (mode_ == ProgramMode::Joints) return {};
    // The block's tool vector: Fanuc G43.5 I J K, Sinumerik A3= B3= C3= (omitted components are 0; with none
    // given the vector stays). Fanuc A-79348E "Tool center point control for 5-axis machining" p. 9; Sinumerik
    // Job Planning 6FC5398-2BP10 sec. 7.2 p. 7-20: "the vector points towards the tool adapter".
    const bool arcMotion = motion_ == Motion::ArcCw || motion_ == Motion::ArcCcw;
    if (tcpSource_ == TcpSource::FanucVector && !arcMotion)
        r.vectorWord = {{static_cast<int8_t>(w.ijk[0]), static_cast<int8_t>(w.ijk[1]), static_cast<int8_t>(w.ijk[2])}};
    const bool anyVector = r.vectorWord[0] >= 0 || r.vectorWord[1] >= 0 || r.vectorWord[2] >= 0;
    if (tcpSource_ != TcpSource::FanucVector && !anyVector) return {};
    r.mode = ProgramMode::TcpVector;
    for (int a = 0; a < layout_.count; ++a)
        if (layout_.rotary[a] && (r.words & (1u << a))) return {"tool vector and rotary axis words in one block", 0, false};
    if (!anyVector) return {};
    r.vectorGiven = true;
    for (int k = 0; k < 3; ++k) {
        r.vector[k] = 0.0;
        if (r.vectorWord[k] < 0) continue;
        const Word& word = b.words[r.vectorWord[k]];
        if (word.kind != ValueKind::Number) return {"tool vector component is not a plain number", 0, false};
        r.vector[k] = wordValue(word);
    }
    if (!(std::hypot(r.vector[0], r.vector[1], r.vector[2]) > 0)) return {"tool vector of length zero", 0, false};
    return {};
}

bool Interpreter::refuseMove(const BlockWords& w, BlockResult& r, bool machineCoordinates, const char* targetProblem) {
    if (machineCoordinates) {
        passThrough(r, "machine-coordinate move (G53 / SUPA), not corrected", 530, false);
        r.machineCoordinates = true;
    } else if (w.foreignAxis) {
        passThrough(r, "axis letter that this machine does not have", 0);
        r.reasonLetter = w.foreignAxis;
    } else if (r.modeSwitch) {
        // Moves of the block that switches tool-tip programming (Fanuc: tool length compensation only) are not
        // corrected; where they end in the new mode is not known here.
        passThrough(r, "move in the block that switches tool-tip programming on or off: not corrected", 0);
        unknownAll(r);
        return true;
    } else if (transform_) {
        passThrough(r, "coordinate transformation active (rotation, scaling, mirror, polar or cylindrical)", 0);
        r.endKnown &= ~r.words;
    } else if (modalMacro_) {
        passThrough(r, "modal macro call (G66) active", 660);
        unknownAll(r);
        return true;
    } else if (cycleActive_ || motion_ == Motion::Cycle) {
        passThrough(r, "canned cycle (not corrected)", 0);
        const int normal = plane_ == 17 ? layout_.axis('Z') : plane_ == 18 ? layout_.axis('Y') : layout_.axis('X');
        if (normal >= 0) r.endKnown &= ~(1u << normal);
    } else if (motion_ == Motion::Unknown) {
        passThrough(r, "no motion mode (G0/G1/G2/G3) in effect", 0);
    } else if (motion_ == Motion::Other) {
        passThrough(r, "threading, probing or spline motion (not corrected)", 0);
        r.endKnown &= ~r.words;
    } else if (targetProblem) {
        passThrough(r, targetProblem, 0);
    } else if (const AxisMask all = layout_.all(); (r.endKnown & all) != all) {
        int missing = 0;
        for (int a = 0; a < layout_.count; ++a)
            if (!(r.endKnown & (1u << a))) {
                missing = layout_.letter[a];
                break;
            }
        passThrough(r, "position of an axis not known yet", 0);
        r.reasonLetter = static_cast<char>(missing);
    } else {
        return false;
    }
    commit(r);
    return true;
}

void Interpreter::convertMotion(const BlockWords& w, const LexedBlock& b, BlockResult& r, bool onlyModal,
                                bool machineCoordinates) {
    const bool isArc = motion_ == Motion::ArcCw || motion_ == Motion::ArcCcw;
    if (r.words == 0 && !r.vectorGiven && !(isArc && w.arcWords && !onlyModal && !cycleActive_ && !machineCoordinates)) {
        if (w.foreignAxis) {
            passThrough(r, "axis letter that this machine does not have", 0);
            r.reasonLetter = w.foreignAxis;
        }
        return;  // no axis motion
    }
    const char* targetProblem = computeTargets(b, r, machineCoordinates);
    if (onlyModal) {
        commit(r);
        return;
    }
    if (refuseMove(w, r, machineCoordinates, targetProblem)) return;
    if (isArc) {
        const char* why = nullptr;
        if (!arcGeometry(b, r, why)) {
            passThrough(r, why, 0);
            commit(r);
            return;
        }
    }
    // An evaluated move: warnings about what was assumed.
    if (!unitsSet_) {
        warn(r, Warning::UnitsAssumed, inch_ ? 1 : 0);
        unitsSet_ = true;
    }
    if (offsetCode_ != 5000 && options_.dialect != Dialect::Printer && !offsetValues(offsetCode_))
        warn(r, Warning::OffsetNotGiven, offsetCode_);
    for (int a = 0; a < layout_.count; ++a)
        if ((assumed_ & ~r.words) & (1u << a)) warn(r, Warning::RotaryAssumed, layout_.letter[a]);
    r.kind = BlockKind::Move;
    commit(r);
}

}  // namespace cnccomp::postproc
