#include "postproc/modal.hpp"

#include <cmath>
#include <cstring>
#include <string_view>

#include <fmt/format.h>

#include "cnccomp/error.hpp"

namespace cnccomp::pp {

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

namespace {

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

bool isControlFlowKeyword(std::string_view id) {
    static constexpr std::string_view kFlow[] = {"IF",    "GOTO",  "GOTOF",   "GOTOB", "GOTOC",   "WHILE", "DO",
                                                 "END",   "ENDWHILE", "LOOP", "ENDLOOP", "REPEAT", "UNTIL", "FOR",
                                                 "ENDFOR", "SUB",  "ENDSUB",  "CALL",  "RETURN",  "RET",   "ENDIF",
                                                 "ELSE",  "ELSEIF", "BREAK",  "CONTINUE", "THEN"};
    for (auto f : kFlow) {
        if (id.size() < f.size()) continue;
        bool same = true;
        for (size_t i = 0; i < f.size() && same; ++i)
            same = static_cast<char>(std::toupper(static_cast<unsigned char>(id[i]))) == f[i];
        if (same && (id.size() == f.size() || std::isdigit(static_cast<unsigned char>(id[f.size()])))) return true;
    }
    return false;
}

enum class Keyword { Harmless, TcpOn, TcpOff, TransformOn, MachineCoords, DiameterOn, DiameterOff, Unknown };

Keyword sinumerikKeyword(std::string_view id, bool call) {
    std::string up;
    for (char c : id) up.push_back(static_cast<char>(std::toupper(static_cast<unsigned char>(c))));
    if (call) return up == "MSG" ? Keyword::Harmless : Keyword::Unknown;
    static constexpr std::string_view kHarmless[] = {
        "SOFT",    "BRISK",   "DRIVE",   "FFWON",  "FFWOF",  "CFC",     "CFTCP",  "CFIN",    "ORIWKS",  "ORIMKS",
        "ORIAXES", "ORIVECT", "ORIEULER", "ORIRPY", "COMPCAD", "COMPCURV", "COMPOF", "COMPON", "UPATH",   "SPATH",
        "STOPRE",  "CUT2D",   "CUT2DF",  "CUT3DC", "FNORM",  "FLIN",    "FCUB",   "WALIMON", "WALIMOF", "G291",
        "G290",    "SPIF1",   "SPIF2",   "OFFN",   "DIAM90", "FGROUP",  "BTAN",   "ETAN",    "FFWOFF"};
    for (auto h : kHarmless)
        if (up == h) return up == "DIAM90" ? Keyword::DiameterOn : Keyword::Harmless;
    if (up == "TRAORI") return Keyword::TcpOn;
    if (up == "TRAFOOF") return Keyword::TcpOff;
    if (up == "TRANSMIT" || up == "TRACYL" || up == "TRANS" || up == "ATRANS" || up == "ROT" || up == "AROT" ||
        up == "SCALE" || up == "ASCALE" || up == "MIRROR" || up == "AMIRROR" || up == "TRAANG")
        return Keyword::TransformOn;
    if (up == "SUPA") return Keyword::MachineCoords;
    if (up == "DIAMON") return Keyword::DiameterOn;
    if (up == "DIAMOF") return Keyword::DiameterOff;
    return Keyword::Unknown;
}

}  // namespace

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

namespace {
bool isDimensionLetter(const AxisLayout& layout, char c) {
    return layout.axis(c) >= 0 || c == 'I' || c == 'J' || c == 'K' || c == 'R' || c == 'U' || c == 'V' || c == 'W';
}
}  // namespace

double Interpreter::wordValue(const Word& w, Dialect dialect, bool inch, const AxisLayout& layout) {
    if (dialect == Dialect::Fanuc && !w.point && isDimensionLetter(layout, w.letter)) return w.value * (inch ? 1e-4 : 1e-3);
    return w.value;
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

void Interpreter::interpret(std::string_view line, const LexedBlock& b, BlockResult& r) {
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
    if (b.percent) return;
    const ProgramMode modeBefore = mode_;
    if (b.count == 0 && b.identifierCount == 0 && (b.flags & kNotEvaluable) == 0) return;
    const Dialect dialect = options_.dialect;
    const AxisMask all = layout_.all();
    r.kind = BlockKind::NoMotion;

    // --- Keywords (multi-letter words) --------------------------------------------------------------------
    uint32_t flags = b.flags;
    bool tcpOn = false, tcpOff = false, transformOn = false, machineKeyword = false, flow = false, unknownKeyword = false;
    int diameterKeyword = -1;
    if (flags & (kIdentifier | kCall)) {
        if (b.identifierCount >= LexedBlock::kMaxIdentifiers) unknownKeyword = true;
        for (int k = 0; k < b.identifierCount; ++k) {
            const std::string_view id = b.identifier(line, k);
            if (isControlFlowKeyword(id)) {
                flow = true;
                continue;
            }
            if (dialect != Dialect::Sinumerik) {
                unknownKeyword = true;
                continue;
            }
            size_t after = b.identifiers[k].end;
            while (after < line.size() && (line[after] == ' ' || line[after] == '\t')) ++after;
            const bool call = after < line.size() && line[after] == '(';
            switch (sinumerikKeyword(id, call)) {
                case Keyword::Harmless: break;
                case Keyword::TcpOn: tcpOn = true; break;
                case Keyword::TcpOff: tcpOff = true; break;
                case Keyword::TransformOn: transformOn = true; break;
                case Keyword::MachineCoords: machineKeyword = true; break;
                case Keyword::DiameterOn: diameterKeyword = 1; break;
                case Keyword::DiameterOff: diameterKeyword = 0; break;
                case Keyword::Unknown: unknownKeyword = true; break;
            }
        }
        if (!flow && !unknownKeyword) flags &= ~(kIdentifier | kCall);
    }

    // --- Words ------------------------------------------------------------------------------------------
    std::array<int, 16> gCode{}, gWord{};
    int nG = 0;
    bool gProblem = false, mCall = false, mSubEnd = false, duplicateAxis = false;
    char foreignAxis = 0;
    const Word *F = nullptr, *H = nullptr, *T = nullptr, *P = nullptr, *L = nullptr, *O = nullptr;
    bool arcWords = false, extProblem = false, userTcpOn = false, userTcpOff = false;
    std::array<int, 3> ijk{{-1, -1, -1}};
    for (int i = 0; i < b.count; ++i) {
        const Word& w = b.words[i];
        const char c = w.letter;
        if (w.ext != 0) {
            // Sinumerik A3= B3= C3=: components of the tool vector (TRAORI); other extended addresses unsupported.
            if (w.ext == 3 && (c == 'A' || c == 'B' || c == 'C')) r.vectorWord[c - 'A'] = static_cast<int8_t>(i);
            else extProblem = true;
            continue;
        }
        if (c == 'G') {
            if (w.kind != ValueKind::Number || w.value < 0 || w.value >= 10000) {
                gProblem = true;
                continue;
            }
            const int code = static_cast<int>(std::lround(w.value * 10));
            if (std::fabs(w.value * 10 - code) > 1e-6 || nG >= 16) {
                gProblem = true;
                continue;
            }
            gCode[nG] = code;
            gWord[nG++] = i;
            continue;
        }
        const int a = layout_.axis(c);
        if (a >= 0) {
            if (r.axisWord[a] >= 0) duplicateAxis = true;
            r.axisWord[a] = static_cast<int8_t>(i);
            r.words |= 1u << a;
            continue;
        }
        switch (c) {
            case 'X': case 'Y': case 'Z': case 'A': case 'B': case 'C': case 'U': case 'V': case 'W':
                if (!foreignAxis) foreignAxis = c;
                break;
            case 'M':
                if (w.kind == ValueKind::Number && w.value == std::floor(w.value)) {
                    const int m = static_cast<int>(w.value);
                    if (m == 0 || m == 1 || m == 2 || m == 30 || m == 60) r.stop = true;
                    if (m == options_.tcpOnM && std::fabs(w.value - m) == 0) userTcpOn = true;
                    if (m == options_.tcpOffM && std::fabs(w.value - m) == 0) userTcpOff = true;
                    if (dialect != Dialect::Printer) {
                        if (m == 98 || m == 97 || m == 198) mCall = true;
                        if (m == 99 || (dialect == Dialect::Sinumerik && m == 17)) mSubEnd = true;
                    }
                }
                break;
            case 'F': F = &w; r.feedWord = i; break;
            case 'H': H = &w; break;
            case 'T': T = &w; break;
            case 'P': P = &w; break;
            case 'L': L = &w; break;
            case 'O': O = &w; break;
            case 'I': case 'J': case 'K':
                ijk[c - 'I'] = i;
                arcWords = true;
                break;
            case 'R': arcWords = true; break;
            default: break;
        }
    }

    // --- Blocks that change the flow of the program or that we cannot read ------------------------------
    const bool rs274o = O && dialect == Dialect::Rs274ngc;
    if (flow || rs274o) {
        passThrough(r, "program flow (o-word, loop, jump, condition or subroutine)", 0);
        unknownAll(r);
        return;
    }
    if (unknownKeyword) {
        passThrough(r, "unknown keyword or call", 0);
        unknownAll(r);
        return;
    }
    if (mCall || mSubEnd) {
        passThrough(r, mCall ? "subprogram call (M98/M97)" : "end of subprogram or jump (M99/M17)", 0);
        unknownAll(r);
        return;
    }
    constexpr uint32_t kValueFlags = kExpression | kVariable | kAssignment | kMissingValue | kBadNumber | kExponent;
    if (flags & kNotEvaluable & ~kValueFlags) {
        passThrough(r, lexFlagReason(flags & kNotEvaluable & ~kValueFlags), 0);
        unknownAll(r);
        motion_ = Motion::Unknown;
        return;
    }
    bool onlyModal = false;
    if (flags & kValueFlags) {
        passThrough(r, lexFlagReason(flags & kValueFlags), 0);
        if (gProblem) {
            unknownAll(r);
            motion_ = Motion::Unknown;
            return;
        }
        onlyModal = true;
    }
    if (gProblem) {
        passThrough(r, "G word that is not a plain G code", 0);
        unknownAll(r);
        motion_ = Motion::Unknown;
        return;
    }
    if (duplicateAxis) {
        passThrough(r, "the same axis twice in one block", 0);
        unknownAll(r);
        return;
    }
    if (O && dialect == Dialect::Fanuc) {
        // O1234: start of a (sub)program. The position is whatever the caller left.
        resetPositions();
        r.endKnown = known_;
        r.end = pos_;
    }

    // --- G codes: classify, then apply in the RS274NGC order of execution -------------------------------
    std::array<GKind, 16> kind{};
    int motionIndex = -1, nonModalIndex = -1;
    for (int k = 0; k < nG; ++k) {
        kind[k] = classifyG(gCode[k], dialect);
        const GKind g = kind[k];
        if (g == GKind::Unknown) {
            passThrough(r, "G code not supported", gCode[k]);
            unknownAll(r);
            motion_ = Motion::Unknown;
            return;
        }
        // G80 next to G0/G1 (common in program headers) cancels the cycle first: not a second motion code.
        const bool isMotion = g == GKind::Rapid || g == GKind::Linear || g == GKind::ArcCw || g == GKind::ArcCcw ||
                              g == GKind::OtherMotion || g == GKind::Cycle || g == GKind::UnknownMotion;
        const bool isNonModal = g == GKind::Dwell || g == GKind::Home || g == GKind::MachineCoords ||
                                g == GKind::OffsetData || g == GKind::PositionOffset || g == GKind::LocalOffset ||
                                g == GKind::FanucG50 || g == GKind::MacroCall || g == GKind::Skip ||
                                g == GKind::ConsumesAxes || g == GKind::TransformToggle || g == GKind::ToolLengthDynamic ||
                                g == GKind::ModalMacro;
        if (isMotion) {
            if (motionIndex >= 0) {
                passThrough(r, "two motion codes in one block", 0);
                unknownAll(r);
                return;
            }
            motionIndex = k;
        }
        if (isNonModal) {
            if (nonModalIndex >= 0) {
                passThrough(r, "two non-modal codes in one block", 0);
                unknownAll(r);
                return;
            }
            nonModalIndex = k;
        }
    }
    auto has = [&](GKind g) {
        for (int k = 0; k < nG; ++k)
            if (kind[k] == g) return true;
        return false;
    };
    auto gIndex = [&](GKind g) {
        for (int k = 0; k < nG; ++k)
            if (kind[k] == g) return k;
        return -1;
    };
    const GKind nonModal = nonModalIndex >= 0 ? kind[nonModalIndex] : GKind::Harmless;
    if (nonModal == GKind::MacroCall) {
        passThrough(r, "macro call (G65)", 0);
        unknownAll(r);
        return;
    }
    // Feed mode and feed.
    if (has(GKind::FeedInverse)) feedMode_ = FeedMode::InverseTime;
    if (has(GKind::FeedMinute)) feedMode_ = FeedMode::PerMinute;
    if (has(GKind::FeedRev)) feedMode_ = FeedMode::PerRevolution;
    if (F && F->kind == ValueKind::Number) feed_ = F->value;
    if (T && T->kind == ValueKind::Number && T->value >= 0 && T->value < 1e6) tool_ = static_cast<int>(T->value);
    // Plane, units, cutter compensation.
    if (has(GKind::PlaneXY)) plane_ = 17;
    if (has(GKind::PlaneZX)) plane_ = 18;
    if (has(GKind::PlaneYZ)) plane_ = 19;
    if (has(GKind::PlaneOther)) plane_ = 0;
    if (has(GKind::Inch)) inch_ = true, unitsSet_ = true;
    if (has(GKind::Metric)) inch_ = false, unitsSet_ = true;
    if (has(GKind::CutterComp)) {
        if (!cutterComp_) warn(r, Warning::CutterCompensation, 0);
        cutterComp_ = true;
    }
    if (has(GKind::CutterCompCancel)) cutterComp_ = false;
    // Tool length.
    if (has(GKind::ToolLength) || has(GKind::ToolLengthNeg) || has(GKind::Tcp)) {
        int number = tool_;
        if (H && H->kind == ValueKind::Number && H->value >= 0 && H->value < 1e6) number = static_cast<int>(H->value);
        const auto len = options_.setup.toolLength(number);
        if (!len) warn(r, Warning::ToolLengthNotGiven, number);
        tloLength_ = len ? *len : options_.setup.defaultToolLength;
        tloAssumed_ = !len && !options_.setup.defaultToolLengthGiven;
        tloSign_ = has(GKind::ToolLengthNeg) ? -1 : 1;
        tloKnown_ = true;
        if (layout_.zAxis < 0) warn(r, Warning::NoToolLengthAxis, 0);
        if (const int k = gIndex(GKind::Tcp); k >= 0) {
            // Fanuc tool centre point control: G43.4 type 1 (rotary angles), G43.5 type 2 (I J K vector).
            mode_ = gCode[k] == 435 ? ProgramMode::TcpVector : ProgramMode::TcpAngles;
            tcpSource_ = gCode[k] == 435 ? TcpSource::FanucVector : TcpSource::FanucAngles;
        }
    }
    if (nonModal == GKind::ToolLengthDynamic) {
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
    if (has(GKind::ToolLengthUnknown)) tloKnown_ = false;
    if (has(GKind::ToolLengthCancel)) {
        tloSign_ = 0;
        tloLength_ = 0;
        tloKnown_ = true;
        tloAssumed_ = false;
        if (tcpSource_ == TcpSource::FanucAngles || tcpSource_ == TcpSource::FanucVector) {
            mode_ = ProgramMode::Joints;
            tcpSource_ = TcpSource::None;
        }
    }
    // Work offset.
    if (const int k = gIndex(GKind::WorkOffset); k >= 0) {
        int p = 0;
        if (gCode[k] == 541) {
            if (!P || P->kind != ValueKind::Number || P->value < 1 || P->value > 300) {
                passThrough(r, "G54.1 without a valid P number", 541);
                unknownAll(r);
                return;
            }
            p = static_cast<int>(P->value);
        }
        offsetCode_ = offsetCodeOfG(gCode[k] / 10.0, p);
    }
    // Distance modes, lathe diameter mode, transformations, modal macros, TCP keywords.
    if (has(GKind::Absolute)) absolute_ = true;
    if (has(GKind::Incremental)) absolute_ = false;
    if (has(GKind::ArcAbsolute)) arcAbsolute_ = true;
    if (has(GKind::ArcIncremental)) arcAbsolute_ = false;
    if (has(GKind::Diameter) || diameterKeyword == 1) diameter_ = true;
    if (has(GKind::Radius) || diameterKeyword == 0) diameter_ = false;
    if (has(GKind::TransformOn) || transformOn) transform_ = true;
    if (has(GKind::TransformOff)) transform_ = false;
    if (nonModal == GKind::TransformToggle) {
        bool on = false;
        for (int a = 0; a < layout_.count; ++a)
            if (r.axisWord[a] >= 0 && b.words[r.axisWord[a]].value != 0) on = true;
        transform_ = on;
    }
    if (nonModal == GKind::ModalMacro) modalMacro_ = true;
    if (has(GKind::ModalMacroCancel)) modalMacro_ = false;
    if (tcpOn) {
        mode_ = ProgramMode::TcpAngles;
        tcpSource_ = TcpSource::Sinumerik;
    }
    if (tcpOff) {
        mode_ = ProgramMode::Joints;
        tcpSource_ = TcpSource::None;
        transform_ = false;
    }
    // A user-declared switch (--tcp-on M428 --tcp-off M429: LinuxCNC's switchable trt kinematics, whose remapped M
    // codes run before the block's motion, modal group 10).
    if (userTcpOn) {
        mode_ = ProgramMode::TcpAngles;
        tcpSource_ = TcpSource::UserSwitch;
    }
    if (userTcpOff && tcpSource_ == TcpSource::UserSwitch) {
        mode_ = ProgramMode::Joints;
        tcpSource_ = TcpSource::None;
    }
    if (mode_ != modeBefore) r.modeSwitch = true;
    if (has(GKind::PositionOffsetCancel)) g92Unknown_ = 0;
    if (has(GKind::PositionOffsetRestore)) g92Unknown_ = all;
    // Motion mode.
    if (has(GKind::CycleCancel)) {
        if (dialect == Dialect::Rs274ngc && motionIndex < 0) motion_ = Motion::Unknown;
        cycleActive_ = false;
        if (motion_ == Motion::Cycle) motion_ = Motion::Unknown;
    }
    if (motionIndex >= 0) {
        r.motionWord = gWord[motionIndex];
        r.motionCode = true;
        switch (kind[motionIndex]) {
            case GKind::Rapid: motion_ = Motion::Rapid; cycleActive_ = false; break;
            case GKind::Linear: motion_ = Motion::Linear; cycleActive_ = false; break;
            case GKind::ArcCw: motion_ = Motion::ArcCw; cycleActive_ = false; break;
            case GKind::ArcCcw: motion_ = Motion::ArcCcw; cycleActive_ = false; break;
            case GKind::OtherMotion: motion_ = Motion::Other; cycleActive_ = false; break;
            case GKind::Cycle:
                if (dialect == Dialect::Rs274ngc) motion_ = Motion::Cycle;
                else cycleActive_ = true;
                break;
            case GKind::UnknownMotion:
                passThrough(r, "tool axis control (G53.1)", 0);
                unknownAll(r);
                return;
            default: break;
        }
    }
    fillConversions(r);
    r.motion = motion_;

    // --- Non-modal codes that use the axis words for something else ------------------------------------
    switch (nonModal) {
        case GKind::Dwell:
        case GKind::ConsumesAxes:
        case GKind::ToolLengthDynamic:
        case GKind::TransformToggle:
        case GKind::ModalMacro:
            return;
        case GKind::OffsetData: {
            const int l = L && L->kind == ValueKind::Number ? static_cast<int>(L->value) : -1;
            const int p = P && P->kind == ValueKind::Number ? static_cast<int>(P->value) : -1;
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
                const Word& w = b.words[r.axisWord[a]];
                if (w.kind != ValueKind::Number) continue;
                const double v = wordValue(w) * (layout_.rotary[a] ? kDeg : (inch_ ? 25.4 : 1.0));
                (*target)[a] = (dialect == Dialect::Fanuc && !absolute_) ? (*target)[a] + v : v;
            }
            for (auto& [c, m] : offsetsUnknown_)
                if (c == code) m &= ~r.words;
            return;
        }
        case GKind::LocalOffset:
            for (int a = 0; a < layout_.count; ++a) {
                if (r.axisWord[a] < 0) continue;
                const Word& w = b.words[r.axisWord[a]];
                if (w.kind != ValueKind::Number) continue;
                local_[a] = wordValue(w) * (layout_.rotary[a] ? kDeg : (inch_ ? 25.4 : 1.0));
            }
            fillConversions(r);
            return;
        case GKind::Home: {
            // Without axis words every axis homes, except rotary axes the program never commands (still taken at 0).
            const AxisMask mask = r.words ? r.words : (all & ~assumed_);
            passThrough(r, "reference point return (position afterwards unknown)", gCode[nonModalIndex], false);
            known_ &= ~mask;
            assumed_ &= ~mask;
            r.endKnown = known_;
            return;
        }
        case GKind::PositionOffset:
        case GKind::FanucG50:
            if (r.words == 0) {
                if (nonModal == GKind::FanucG50) transform_ = false;  // G50 without axes: scaling off / spindle clamp
                return;
            }
            g92Unknown_ |= r.words;
            passThrough(r, "coordinate offset set from the actual position (G92 / G50)", gCode[nonModalIndex]);
            return;
        case GKind::Skip:
            passThrough(r, "skip move (G31)", 310);
            known_ &= ~r.words;
            r.endKnown = known_;
            return;
        case GKind::MachineCoords:
            break;
        default:
            if (machineKeyword) break;
            break;
    }
    const bool machineCoordinates = nonModal == GKind::MachineCoords || machineKeyword;

    if (extProblem) {
        passThrough(r, "address with an extension other than A3= B3= C3= (e.g. Euler angles A2=): not supported", 0);
        unknownAll(r);
        return;
    }
    if (mode_ != ProgramMode::Joints) {
        // The block's tool vector: Fanuc G43.5 I J K, Sinumerik A3= B3= C3= (omitted components are 0; with none
        // given the vector stays). Fanuc A-79348E "Tool center point control for 5-axis machining" p. 9; Sinumerik
        // Job Planning 6FC5398-2BP10 sec. 7.2 p. 7-20: "the vector points towards the tool adapter".
        const bool arcMotion = motion_ == Motion::ArcCw || motion_ == Motion::ArcCcw;
        if (tcpSource_ == TcpSource::FanucVector && !arcMotion) r.vectorWord = {{static_cast<int8_t>(ijk[0]),
                                                                                 static_cast<int8_t>(ijk[1]),
                                                                                 static_cast<int8_t>(ijk[2])}};
        const bool anyVector = r.vectorWord[0] >= 0 || r.vectorWord[1] >= 0 || r.vectorWord[2] >= 0;
        if (tcpSource_ == TcpSource::FanucVector || anyVector) {
            r.mode = ProgramMode::TcpVector;
            for (int a = 0; a < layout_.count; ++a)
                if (layout_.rotary[a] && (r.words & (1u << a))) {
                    passThrough(r, "tool vector and rotary axis words in one block", 0);
                    unknownAll(r);
                    return;
                }
            if (anyVector) {
                r.vectorGiven = true;
                for (int k = 0; k < 3; ++k) {
                    r.vector[k] = 0.0;
                    if (r.vectorWord[k] < 0) continue;
                    const Word& w = b.words[r.vectorWord[k]];
                    if (w.kind != ValueKind::Number) {
                        passThrough(r, "tool vector component is not a plain number", 0);
                        unknownAll(r);
                        return;
                    }
                    r.vector[k] = wordValue(w);
                }
                if (!(std::hypot(r.vector[0], r.vector[1], r.vector[2]) > 0)) {
                    passThrough(r, "tool vector of length zero", 0);
                    unknownAll(r);
                    return;
                }
            }
        }
    }
    // --- Motion --------------------------------------------------------------------------------------------
    const bool isArc = motion_ == Motion::ArcCw || motion_ == Motion::ArcCcw;
    if (r.words == 0 && !r.vectorGiven && !(isArc && arcWords && !onlyModal && !cycleActive_ && !machineCoordinates)) {
        if (foreignAxis) {
            passThrough(r, "axis letter that this machine does not have", 0);
            r.reasonLetter = foreignAxis;
        }
        return;  // no axis motion
    }
    const char* targetProblem = computeTargets(b, r, machineCoordinates);
    if (onlyModal) {
        commit(r);
        return;
    }
    if (machineCoordinates) {
        passThrough(r, "machine-coordinate move (G53 / SUPA), not corrected", 530, false);
        r.machineCoordinates = true;
        commit(r);
        return;
    }
    if (foreignAxis) {
        passThrough(r, "axis letter that this machine does not have", 0);
        r.reasonLetter = foreignAxis;
        commit(r);
        return;
    }
    if (r.modeSwitch) {
        // Moves of the block that switches tool-tip programming (Fanuc: tool length compensation only) are not
        // corrected; where they end in the new mode is not known here.
        passThrough(r, "move in the block that switches tool-tip programming on or off: not corrected", 0);
        unknownAll(r);
        return;
    }
    if (transform_) {
        passThrough(r, "coordinate transformation active (rotation, scaling, mirror, polar or cylindrical)", 0);
        r.endKnown &= ~r.words;
        commit(r);
        return;
    }
    if (modalMacro_) {
        passThrough(r, "modal macro call (G66) active", 660);
        unknownAll(r);
        return;
    }
    if (cycleActive_ || motion_ == Motion::Cycle) {
        passThrough(r, "canned cycle (not corrected)", 0);
        const int normal = plane_ == 17 ? layout_.axis('Z') : plane_ == 18 ? layout_.axis('Y') : layout_.axis('X');
        if (normal >= 0) r.endKnown &= ~(1u << normal);
        commit(r);
        return;
    }
    if (motion_ == Motion::Unknown) {
        passThrough(r, "no motion mode (G0/G1/G2/G3) in effect", 0);
        commit(r);
        return;
    }
    if (motion_ == Motion::Other) {
        passThrough(r, "threading, probing or spline motion (not corrected)", 0);
        r.endKnown &= ~r.words;
        commit(r);
        return;
    }
    if (targetProblem) {
        passThrough(r, targetProblem, 0);
        commit(r);
        return;
    }
    if ((r.endKnown & all) != all) {
        int missing = 0;
        for (int a = 0; a < layout_.count; ++a)
            if (!(r.endKnown & (1u << a))) {
                missing = layout_.letter[a];
                break;
            }
        passThrough(r, "position of an axis not known yet", 0);
        r.reasonLetter = static_cast<char>(missing);
        commit(r);
        return;
    }
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
    if (offsetCode_ != 5000 && dialect != Dialect::Printer && !offsetValues(offsetCode_))
        warn(r, Warning::OffsetNotGiven, offsetCode_);
    for (int a = 0; a < layout_.count; ++a)
        if ((assumed_ & ~r.words) & (1u << a)) warn(r, Warning::RotaryAssumed, layout_.letter[a]);
    r.kind = BlockKind::Move;
    commit(r);
}

}  // namespace cnccomp::pp
