#include "postproc/modal.hpp"

#include "postproc/interp_check.hpp"
#include "postproc/interp_read.hpp"

#include <cmath>
#include <cstring>
#include <string_view>

#include <fmt/format.h>

#include "cnccomp/error.hpp"

namespace cnccomp::postproc {

AxisLayout AxisLayout::fromMachine(const MachineModel& m) {
    AxisLayout l;
    l.ofLetter.fill(-1);
    l.count = m.axisCount();
    for (int i = 0; i < m.axisCount(); ++i) {
        const std::string& name = m.axisNames[i];
        if (name.size() != 1 || !std::isalpha(static_cast<unsigned char>(name[0])))
            throw ModelError(fmt::format("machine '{}': axis '{}' has no one-letter program address", m.name, name));
        const char c = static_cast<char>(std::toupper(static_cast<unsigned char>(name[0])));
        if (c == 'G' || c == 'M' || c == 'N' || c == 'F' || c == 'S' || c == 'T' || c == 'H' || c == 'I' || c == 'J' ||
            c == 'K' || c == 'R' || c == 'P' || c == 'O' || c == 'D' || c == 'L' || c == 'Q')
            throw ModelError(fmt::format("machine '{}': axis letter '{}' is an address of another G-code word", m.name, c));
        const Link& link = m.axisLink(i);
        l.letter[i] = c;
        l.rotary[i] = link.kind == AxisKind::Rotary;
        l.modulo[i] = link.modulo;
        l.ofLetter[c - 'A'] = static_cast<int8_t>(i);
        if (c == 'Z' && !l.rotary[i]) l.zAxis = i;
    }
    return l;
}

AxisLayout AxisLayout::generic() {
    AxisLayout l;
    l.ofLetter.fill(-1);
    const char letters[] = {'X', 'Y', 'Z', 'A', 'B', 'C'};
    l.count = 6;
    for (int i = 0; i < 6; ++i) {
        l.letter[i] = letters[i];
        l.rotary[i] = i >= 3;
        l.ofLetter[letters[i] - 'A'] = static_cast<int8_t>(i);
    }
    l.zAxis = 2;
    return l;
}

Interpreter::Interpreter(const AxisLayout& layout, const InterpreterOptions& options)
    : layout_(layout), options_(options) {
    inch_ = options_.setup.inchDefault;
    local_ = AxisVector::Zero(layout_.count);
    pos_ = AxisVector::Zero(layout_.count);
    for (const WorkOffset& w : options_.setup.offsets) {
        AxisVector v = AxisVector::Zero(layout_.count);
        static constexpr char kLetters[] = {'X', 'Y', 'Z', 'A', 'B', 'C'};
        for (int k = 0; k < 6; ++k) {
            const int a = layout_.axis(kLetters[k]);
            if (a < 0) {
                if (w.xyzabc[k] != 0.0)
                    throw InputError("--work-offset", 0,
                                     fmt::format("{} gives a value for axis {}, which the machine does not have",
                                                 offsetCodeName(w.code), kLetters[k]));
                continue;
            }
            v[a] = layout_.rotary[a] ? w.xyzabc[k] * kDeg : w.xyzabc[k];
        }
        offsets_.emplace_back(w.code, v);
    }
    resetPositions();
}

void Interpreter::resetPositions() {
    known_ = 0;
    assumed_ = 0;
    for (int i = 0; i < layout_.count; ++i)
        if (layout_.rotary[i]) {
            pos_[i] = 0.0;
            known_ |= 1u << i;
            assumed_ |= 1u << i;
        }
    for (const auto& [letter, value] : options_.setup.assumed) {
        const int i = layout_.axis(letter);
        if (i < 0) continue;
        pos_[i] = layout_.rotary[i] ? value * kDeg : value;
        known_ |= 1u << i;
        assumed_ |= 1u << i;
    }
}

void Interpreter::warn(BlockResult& r, Warning w, int code) {
    for (const auto& [kw, kc] : warned_)
        if (kw == w && kc == code) return;
    warned_.emplace_back(w, code);
    if (r.warningCount < static_cast<int>(r.warnings.size())) r.warnings[r.warningCount++] = {w, code};
}

void Interpreter::passThrough(BlockResult& r, const char* reason, int code, bool report) {
    r.kind = BlockKind::PassThrough;
    if (!r.reason) {
        r.reason = reason;
        r.reasonCode = code;
        r.report = report;
    }
}

void Interpreter::unknownAll(BlockResult& r) {
    known_ = 0;
    assumed_ = 0;
    r.endKnown = 0;
}

void Interpreter::unreadLine(BlockResult& r, const char* reason) {
    r = BlockResult{};
    r.start = pos_;
    r.end = pos_;
    r.startKnown = known_;
    r.axisWord.fill(-1);
    passThrough(r, reason, 0);
}

void Interpreter::forgetAll(BlockResult& r, const char* reason) {
    unreadLine(r, reason);
    unknownAll(r);
    motion_ = Motion::Unknown;
}

bool Interpreter::forgetOverlong(const OverlongLine& l, BlockResult& r) {
    static constexpr char kModal[] = "GMOLPQHDTEUVWIJKR";
    bool modal = l.other;
    for (const char* c = kModal; *c && !modal; ++c)
        if (layout_.axis(*c) < 0 && l.has(*c)) modal = true;
    const char* why = "line longer than the read buffer";
    if (modal) {
        forgetAll(r, why);
        return true;
    }
    AxisMask named = 0;
    for (int a = 0; a < layout_.count; ++a)
        if (l.has(layout_.letter[a])) named |= 1u << a;
    unreadLine(r, why);
    known_ &= ~named;
    assumed_ &= ~named;
    r.endKnown = known_;
    r.words = named;
    return false;
}

const AxisVector* Interpreter::offsetValues(int code) const {
    for (const auto& [c, v] : offsets_)
        if (c == code) return &v;
    return nullptr;
}

AxisMask Interpreter::offsetUnknown(int code) const {
    for (const auto& [c, m] : offsetsUnknown_)
        if (c == code) return m;
    return 0;
}

void Interpreter::fillConversions(BlockResult& r) const {
    const double lin = inch_ ? 25.4 : 1.0;
    const AxisVector* work = offsetValues(offsetCode_);
    r.scale.resize(layout_.count);
    r.offset.resize(layout_.count);
    r.wrap = 0;
    for (int i = 0; i < layout_.count; ++i) {
        if (layout_.rotary[i]) {
            r.scale[i] = kDeg;
        } else {
            r.scale[i] = lin;
            if (diameter_ && layout_.letter[i] == 'X') r.scale[i] = 0.5 * lin;
        }
        r.offset[i] = (work ? (*work)[i] : 0.0) + local_[i];
        // In TCP mode the words are the tool point itself: no tool length shift of Z.
        if (i == layout_.zAxis && mode_ == ProgramMode::Joints) r.offset[i] += tloSign_ * tloLength_;
        if (options_.rotaryShortest && layout_.rotary[i] && layout_.modulo[i]) r.wrap |= 1u << i;
    }
    r.absolute = absolute_;
    r.arcAbsolute = arcAbsolute_;
    r.inch = inch_;
    r.integerIncrements = options_.dialect == Dialect::Fanuc;
    r.increment = inch_ ? 1e-4 : 1e-3;
    r.feedMode = feedMode_;
    r.feed = feed_;
    r.tipLength = tloSign_ != 0 ? tloLength_ : options_.setup.defaultToolLength;
    r.tipLengthAssumed = tloSign_ != 0 ? tloAssumed_ : !options_.setup.defaultToolLengthGiven;
    r.mode = mode_;
    r.tcpSource = tcpSource_;
    // The controller's tool length in TCP mode: the active G43 / G43.4 / G43.5 offset; Sinumerik always works with
    // the active tool's length (--tool-length); LinuxCNC's trt kinematics take motion.tooloffset.z (0 without G43).
    r.controlLength = tloSign_ != 0 ? tloSign_ * tloLength_
                      : options_.dialect == Dialect::Sinumerik ? options_.setup.defaultToolLength
                                                               : 0.0;
    r.rapidIsFeed = options_.dialect == Dialect::Printer;
}

bool Interpreter::arcGeometry(const LexedBlock& b, BlockResult& r, const char*& why) {
    int a0, a1, an;
    char l0, l1, o0, o1;
    if (plane_ == 17) {
        a0 = layout_.axis('X'), a1 = layout_.axis('Y'), an = layout_.axis('Z');
        l0 = 'I', l1 = 'J', o0 = 'X', o1 = 'Y';
    } else if (plane_ == 18) {
        a0 = layout_.axis('Z'), a1 = layout_.axis('X'), an = layout_.axis('Y');
        l0 = 'K', l1 = 'I', o0 = 'Z', o1 = 'X';
    } else if (plane_ == 19) {
        a0 = layout_.axis('Y'), a1 = layout_.axis('Z'), an = layout_.axis('X');
        l0 = 'J', l1 = 'K', o0 = 'Y', o1 = 'Z';
    } else {
        why = "arc in a plane other than G17/G18/G19";
        return false;
    }
    (void)o0;
    (void)o1;
    if (a0 < 0 || a1 < 0 || layout_.rotary[a0] || layout_.rotary[a1]) {
        why = "arc plane axis missing on this machine";
        return false;
    }
    if (diameter_) {
        why = "arc in diameter mode";
        return false;
    }
    const AxisMask all = layout_.all();
    if ((r.startKnown & all) != all) {
        why = "arc start position not known";
        return false;
    }
    ArcGeometry& g = r.arc;
    g.axis0 = a0;
    g.axis1 = a1;
    g.normal = an >= 0 && !layout_.rotary[an] ? an : -1;
    const double s0 = r.start[a0], s1 = r.start[a1], e0 = r.end[a0], e1 = r.end[a1];
    const Word* R = b.find('R');
    const Word* W0 = b.find(l0);
    const Word* W1 = b.find(l1);
    const double lin = inch_ ? 25.4 : 1.0;
    const bool cw = r.motion == Motion::ArcCw;
    g.turns = 1;
    if (const Word* P = b.find('P'); P && options_.dialect == Dialect::Rs274ngc) {
        if (P->value < 1 || P->value != std::floor(P->value) || P->value > 1000) {
            why = "arc P (turns) is not a positive integer";
            return false;
        }
        g.turns = static_cast<int>(P->value);
    }
    if (R) {
        if (W0 || W1) {
            why = "arc with both R and I/J/K";
            return false;
        }
        g.radiusForm = true;
        const double rad = wordValue(*R) * lin;
        const double dx = e0 - s0, dy = e1 - s1, d = std::hypot(dx, dy);
        if (!(std::fabs(rad) > 0) || d < 1e-9) {
            why = "R arc with zero radius or coincident end points";
            return false;
        }
        const double half = d / 2, ar = std::fabs(rad);
        if (half > ar * (1 + 1e-9) + 1e-6) {
            why = "R arc radius smaller than half the chord";
            return false;
        }
        const double h = half >= ar ? 0.0 : std::sqrt(ar * ar - half * half);
        // Centre to the right of start→end for G2 with R > 0 (≤ 180°), to the left for G3; R < 0 flips.
        double side = cw ? 1.0 : -1.0;
        if (rad < 0) side = -side;
        g.c0 = (s0 + e0) / 2 + side * h * dy / d;
        g.c1 = (s1 + e1) / 2 - side * h * dx / d;
    } else {
        if (!W0 && !W1) {
            why = "arc without I/J/K or R";
            return false;
        }
        const double i0 = W0 ? wordValue(*W0) * lin : 0.0, i1 = W1 ? wordValue(*W1) * lin : 0.0;
        if (arcAbsolute_) {
            // G90.1: centre in program coordinates, like an absolute axis word.
            g.c0 = i0 + (r.offset[a0]);
            g.c1 = i1 + (r.offset[a1]);
        } else {
            g.c0 = s0 + i0;
            g.c1 = s1 + i1;
        }
    }
    const double r0 = std::hypot(s0 - g.c0, s1 - g.c1), r1 = std::hypot(e0 - g.c0, e1 - g.c1);
    if (r0 < 1e-9) {
        why = "arc with zero radius";
        return false;
    }
    if (std::fabs(r0 - r1) > 0.01 + 1e-3 * r0) {
        why = "arc end point not on the circle (start and end radius differ)";
        return false;
    }
    const double t0 = std::atan2(s1 - g.c1, s0 - g.c0), t1 = std::atan2(e1 - g.c1, e0 - g.c0);
    double sweep = t1 - t0;
    const bool closed = std::hypot(e0 - s0, e1 - s1) < 1e-12;
    if (cw) {
        if (closed) sweep = -kTwoPi;
        else {
            while (sweep >= 0) sweep -= kTwoPi;
            while (sweep < -kTwoPi) sweep += kTwoPi;
        }
        sweep -= kTwoPi * (g.turns - 1);
    } else {
        if (closed) sweep = kTwoPi;
        else {
            while (sweep <= 0) sweep += kTwoPi;
            while (sweep > kTwoPi) sweep -= kTwoPi;
        }
        sweep += kTwoPi * (g.turns - 1);
    }
    g.sweep = sweep;
    return true;
}

const char* Interpreter::computeTargets(const LexedBlock& b, BlockResult& r, bool machineCoordinates) const {
    const char* why = nullptr;
    const AxisMask offsetsUnknown = offsetUnknown(offsetCode_) | g92Unknown_;
    for (int a = 0; a < layout_.count; ++a) {
        const int wi = r.axisWord[a];
        if (wi < 0) continue;
        const Word& w = b.words[wi];
        const AxisMask bit = 1u << a;
        if (w.kind != ValueKind::Number) {
            r.endKnown &= ~bit;
            if (!why) why = "axis word is not a plain number";
            continue;
        }
        const double v = wordValue(w);
        if (!(std::fabs(v) < 1e7)) {
            r.endKnown &= ~bit;
            if (!why) why = "axis value out of range";
            continue;
        }
        if (machineCoordinates) {
            r.end[a] = v * (layout_.rotary[a] ? kDeg : (inch_ ? 25.4 : 1.0));
            r.endKnown |= bit;
        } else if (absolute_) {
            if ((offsetsUnknown & bit) || (a == layout_.zAxis && !tloKnown_)) {
                r.endKnown &= ~bit;
                if (!why) why = "coordinate offset unknown (G92, G10 L20 or G43.2)";
                continue;
            }
            double t = v * r.scale[a] + r.offset[a];
            if ((r.wrap & bit) && (r.startKnown & bit)) t += kTwoPi * std::round((r.start[a] - t) / kTwoPi);
            r.end[a] = t;
            r.endKnown |= bit;
        } else {
            if (!(r.startKnown & bit)) {
                r.endKnown &= ~bit;
                if (!why) why = "incremental move from an unknown position";
                continue;
            }
            r.end[a] = r.start[a] + v * r.scale[a];
            r.endKnown |= bit;
        }
    }
    return why;
}

void Interpreter::commit(const BlockResult& r) {
    pos_ = r.end;
    known_ = r.endKnown;
    assumed_ &= ~r.words;
    assumed_ &= known_;
}

void Interpreter::beginBlock(BlockResult& r) {
    r.kind = BlockKind::Empty;
    r.motion = motion_;
    r.motionWord = -1;
    r.motionCode = false;
    r.start = pos_;
    r.end = pos_;
    r.startKnown = known_;
    r.endKnown = known_;
    r.words = 0;
    r.axisWord.fill(-1);
    r.arc = ArcGeometry{};
    r.feedWord = -1;
    r.stop = false;
    r.reason = nullptr;
    r.reasonCode = 0;
    r.reasonLetter = 0;
    r.machineCoordinates = false;
    r.report = true;
    r.warningCount = 0;
    r.modeSwitch = false;
    r.vectorWord = {{-1, -1, -1}};
    r.vectorGiven = false;
    fillConversions(r);
}

// The driver: read (postproc/interp_read.hpp), check (interp_check.hpp), convert (interp_convert.cpp), as LinuxCNC's
// Interp::read → check_items → execute_block (src/emc/rs274ngc/rs274ngc_pre.cc, interp_read.cc, interp_check.cc,
// interp_convert.cc). A refused block is passed through; what it makes unknown stays unknown until commanded again.
void Interpreter::interpret(std::string_view line, const LexedBlock& b, BlockResult& r) {
    beginBlock(r);
    if (b.percent) return;
    if (b.count == 0 && b.identifierCount == 0 && (b.flags & kNotEvaluable) == 0) return;
    const ProgramMode modeBefore = mode_;
    const Dialect dialect = options_.dialect;
    r.kind = BlockKind::NoMotion;

    BlockWords w;
    readBlockWords(line, b, layout_, options_, w, r);

    const WordCheck checked = checkWords(w, dialect);
    if (checked.onlyModalReason) passThrough(r, checked.onlyModalReason, 0);
    if (checked.refusal) return refuse(r, checked.refusal);
    const bool onlyModal = checked.onlyModalReason != nullptr;
    if (w.O && dialect == Dialect::Fanuc) {
        // O1234: start of a (sub)program. The position is whatever the caller left.
        resetPositions();
        r.endKnown = known_;
        r.end = pos_;
    }
    GCodes g;
    if (const Refusal why = checkGCodes(w, dialect, g)) return refuse(r, why);

    if (const Refusal why = convertModalCodes(w, g, b, r, modeBefore)) return refuse(r, why);
    fillConversions(r);
    r.motion = motion_;
    if (convertNonModal(w, g, b, r)) return;
    const bool machineCoordinates = g.nonModal == GKind::MachineCoords || w.machineKeyword;
    if (const Refusal why = convertToolVector(w, b, r)) return refuse(r, why);
    convertMotion(w, b, r, onlyModal, machineCoordinates);
}

}  // namespace cnccomp::postproc
