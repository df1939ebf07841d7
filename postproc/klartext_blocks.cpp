#include "postproc/klartext_blocks.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/text_util.hpp"

namespace cnccomp::postproc {
using namespace cnccomp::io;
namespace {

std::string klartextUpper(std::string_view s) {
    std::string o;
    o.reserve(s.size());
    for (char c : s) o.push_back(static_cast<char>(std::toupper(static_cast<unsigned char>(c))));
    return o;
}

bool klartextNumberStart(char c) { return c == '+' || c == '-' || c == '.' || std::isdigit(static_cast<unsigned char>(c)); }

bool klartextIsMWord(const std::string& t) { return t.size() > 1 && t.front() == 'M' && std::isdigit(static_cast<unsigned char>(t[1])); }

}  // namespace

void tokenizeKlartext(std::string_view text, std::vector<KlartextToken>& tokens) {
    tokens.clear();
    size_t lineBegin = 0;
    while (lineBegin <= text.size()) {
        size_t lineEnd = lineBegin;
        while (lineEnd < text.size() && text[lineEnd] != '\n' && text[lineEnd] != '\r') ++lineEnd;
        // Code: before ';', without a trailing '~'.
        size_t codeEnd = lineBegin;
        while (codeEnd < lineEnd && text[codeEnd] != ';') ++codeEnd;
        size_t e = codeEnd;
        while (e > lineBegin && std::isspace(static_cast<unsigned char>(text[e - 1]))) --e;
        if (e > lineBegin && text[e - 1] == '~') codeEnd = e - 1;
        size_t i = lineBegin;
        while (i < codeEnd) {
            while (i < codeEnd && std::isspace(static_cast<unsigned char>(text[i]))) ++i;
            size_t j = i;
            if (j < codeEnd && text[j] == '"') {  // quoted tool name
                ++j;
                while (j < codeEnd && text[j] != '"') ++j;
                if (j < codeEnd) ++j;
            } else {
                while (j < codeEnd && !std::isspace(static_cast<unsigned char>(text[j]))) ++j;
            }
            if (j > i) tokens.push_back({static_cast<uint32_t>(i), static_cast<uint32_t>(j)});
            i = j;
        }
        if (lineEnd >= text.size()) break;
        lineBegin = lineEnd + 1;
        if (text[lineEnd] == '\r' && lineBegin < text.size() && text[lineBegin] == '\n') ++lineBegin;
    }
}

bool klartextBlockNumber(std::string_view t, uint64_t& number) {
    if (t.empty() || t.size() > 18) return false;
    uint64_t v = 0;
    for (char c : t) {
        if (!std::isdigit(static_cast<unsigned char>(c))) return false;
        v = v * 10 + static_cast<uint64_t>(c - '0');
    }
    number = v;
    return true;
}

/// Parsed words of a path block.
struct KlartextInterpreter::Words {
    std::vector<KlartextAxisWord> axes;
    int dr = 0;                  ///< +1 DR+, −1 DR−, 0 none
    bool rapid = false;          ///< FMAX
    bool machine = false;        ///< M91 / M92
    bool m128 = false, m129 = false;
    bool hasR = false;           ///< CR radius
    double radius = 0;
    bool hasPR = false, incPR = false, hasPA = false, incPA = false;
    double pr = 0, pa = 0;
};

KlartextInterpreter::KlartextInterpreter(const AxisLayout& layout, const Setup& setup, std::string inputName)
    : L_(layout), setup_(setup), inputName_(std::move(inputName)) {
    pos_ = AxisVector::Zero(L_.count);
    shift_ = AxisVector::Zero(L_.count);
    for (int a = 0; a < L_.count; ++a)
        if (L_.rotary[a]) known_ |= 1u << a;  // rotary axes at 0 until programmed
    for (const auto& [letter, value] : setup_.assumed) {
        const int a = L_.axis(static_cast<char>(std::toupper(static_cast<unsigned char>(letter))));
        if (a < 0) continue;
        pos_[a] = L_.rotary[a] ? value * kDeg : value;
        known_ |= 1u << a;
    }
    toolAxis_ = L_.axis('Z');
    tip_ = setup_.defaultToolLength;
    tipAssumed_ = !setup_.defaultToolLengthGiven;
}

void KlartextInterpreter::fail(const std::string& what) const { throw InputError(inputName_, static_cast<int>(line_), what); }

void KlartextInterpreter::interpret(std::string_view text, uint64_t line, KlartextBlock& b) {
    line_ = line;
    b.kind = KlartextKind::Empty;
    b.motion = Motion::Unknown;
    b.polar = b.machine = b.hasM = b.arcKnown = false;
    b.tcpOnAtStart = b.tcpOffAtEnd = b.modeSwitch = false;
    b.numberToken = b.keyToken = b.radiusCompToken = -1;
    b.axes.clear();
    b.dropTokens.clear();
    b.reason.clear();
    b.words = 0;
    b.start = b.end = pos_;
    b.startKnown = b.endKnown = known_;
    b.mode = mode_;
    b.controlLength = tlo_;
    b.tipLength = tip_;
    b.tipLengthAssumed = tipAssumed_;
    tokenizeKlartext(text, b.tokens);
    tok_.clear();
    for (const KlartextToken& t : b.tokens) tok_.push_back(klartextUpper(text.substr(t.begin, t.end - t.begin)));
    size_t k = 0;
    uint64_t number = 0;
    if (k < tok_.size() && klartextBlockNumber(tok_[k], number)) b.numberToken = static_cast<int>(k++);
    if (k >= tok_.size()) return;
    b.keyToken = static_cast<int>(k);
    if (ended_) fail("block after END PGM");
    try {
        dispatch(text, b);
    } catch (const Unsupported& u) {
        forget(u, text, b);
    }
}

void KlartextInterpreter::forget(const Unsupported& u, std::string_view, KlartextBlock& b) {
    b.kind = KlartextKind::Unsupported;
    b.reason = u.reason;
    b.motion = Motion::Unknown;
    AxisMask lose = 0, linear = 0;
    for (int a = 0; a < L_.count; ++a)
        if (!L_.rotary[a]) linear |= 1u << a;
    if (u.forget == 1) {
        // The axes the block names (letters, or I + letter, followed by anything).
        for (size_t i = static_cast<size_t>(b.keyToken) + 1; i < tok_.size(); ++i) {
            const std::string& t = tok_[i];
            const size_t p = t.size() > 1 && t[0] == 'I' && L_.axis(t[1]) >= 0 ? 1 : 0;
            if (t.size() > p + 1 && L_.axis(t[p]) >= 0 && (klartextNumberStart(t[p + 1]) || t[p + 1] == 'Q'))
                lose |= 1u << L_.axis(t[p]);
        }
    } else if (u.forget == 2) {
        lose = linear;
    } else if (u.forget == 3) {
        lose = L_.all();
    }
    if (tok_[static_cast<size_t>(b.keyToken)] == "CC") {
        lose = 0;  // a pole with a Q parameter: the pole is not known
        poleKnown_ = false;
    }
    known_ &= ~lose;
    if (u.forget >= 1) {
        tangentKnown_ = false;
        forgotAny_ = true;
    }
    if (u.forget == 3) poleKnown_ = false;
    b.words = lose;
    b.end = pos_;
    b.endKnown = known_;
}

void KlartextInterpreter::dispatch(std::string_view text, KlartextBlock& b) {
    const size_t k = static_cast<size_t>(b.keyToken);
    const std::string& key = tok_[k];
    const std::vector<std::string> rest(tok_.begin() + static_cast<long>(k) + 1, tok_.end());
    if (key == "*") return;  // structure block
    b.kind = KlartextKind::NoMotion;
    if (key == "BEGIN") return begin(rest);
    if (key == "END") {
        if (rest.empty() || rest[0] != "PGM") fail("expected END PGM");
        ended_ = true;
        return;
    }
    if (key == "BLK") return;  // workpiece blank for the graphics
    if (key == "TOOL") return tool(rest);
    if (key == "STOP") return mOnly(rest, b);
    if (key == "CYCL") return cycle(rest);
    if (key == "FUNCTION") return function(rest, b);
    if (key == "PLANE") return plane(rest);
    const bool moving = key == "L" || key == "C" || key == "CR" || key == "CT" || key == "LP" || key == "CP";
    if (moving && transformLine_)
        unsupported(fmt::format("a coordinate transformation is active (PLANE / TRANS / cycle at line {}): positions in "
                                "the transformed frame are not evaluated until PLANE RESET",
                                transformLine_),
                    1);
    if (moving && tcpUnsupportedLine_)
        unsupported(fmt::format("FUNCTION TCPM at line {} is active with options not evaluated (AXIS SPAT, PATHCTRL VECTOR "
                                "or REFPNT): until FUNCTION RESET TCPM",
                                tcpUnsupportedLine_),
                    1);
    if (key == "L") return linear(text, b);
    if (key == "CC") return pole(text, b);
    if (key == "C" || key == "CR" || key == "CT") return circle(key, text, b);
    if (key == "LP" || key == "CP") return polarBlock(key, text, b);
    if (klartextIsMWord(key)) {
        std::vector<std::string> all{key};
        all.insert(all.end(), rest.begin(), rest.end());
        return mOnly(all, b);
    }
    if (key == "LBL" || key == "CALL")
        unsupported(fmt::format("{} (labels, subprogram calls and repeats) is not evaluated by cnccomp's Klartext reader: "
                                "write the program out without them",
                                key == "LBL" ? "LBL" : "CALL " + (rest.empty() ? "" : rest[0])),
                    3);
    if (key.front() == 'Q' || key == "FN") unsupported("Q parameters and FN functions are not evaluated by cnccomp's Klartext reader", 0);
    if (key == "RND" || key == "CHF") unsupported(key + " (corner rounding / chamfer) is not evaluated by cnccomp's Klartext reader", 0);
    if (key == "APPR" || key == "DEP" || key == "SPL" || key == "FL" || key == "FLT" || key == "FC" || key == "FCT" ||
        key == "FPOL" || key == "FSELECT")
        unsupported(fmt::format("{} (approach / departure, spline, FK free contour) is not evaluated by cnccomp's Klartext reader",
                                key),
                    2);
    if (key == "LN") unsupported("LN (straight line with a surface normal vector) is not evaluated by cnccomp's Klartext reader", 1);
    if (key == "TRANS") {
        transformLine_ = line_;
        unsupported("TRANS (coordinate transformation) is not evaluated by cnccomp's Klartext reader", 3);
    }
    unsupported(fmt::format("'{}' is not evaluated by cnccomp's Klartext reader (read: L, C, CC, CR, CT, LP, CP, TOOL CALL, "
                            "CYCL DEF 7/9, STOP, M, M128/M129, FUNCTION TCPM)",
                            text.substr(b.tokens[k].begin, b.tokens[k].end - b.tokens[k].begin)),
                3);
}

void KlartextInterpreter::begin(const std::vector<std::string>& rest) {
    if (rest.size() < 2 || rest[0] != "PGM") fail("expected BEGIN PGM <name> MM|INCH");
    if (rest.size() >= 3) {
        if (rest[2] == "INCH") inch_ = true;
        else if (rest[2] != "MM") fail(fmt::format("unit '{}' after BEGIN PGM: expected MM or INCH", rest[2]));
    }
}

double KlartextInterpreter::number(std::string_view text, std::string_view what) const {
    if (!text.empty() && (text.front() == 'Q' || ((text.front() == '+' || text.front() == '-') && text.size() > 1 && text[1] == 'Q')))
        unsupported(fmt::format("{}: Q parameters are not evaluated by cnccomp's Klartext reader", what), 1);
    // Klartext numbers are plain decimals; an exponent ("1e3") is refused, not read as something else.
    if (text.find_first_of("eE") != std::string_view::npos)
        fail(fmt::format("{}: '{}' is not a number (exponent notation is not Klartext: write the digits out)", what, text));
    const auto v = parseNumber(text);
    if (!v || !std::isfinite(*v)) fail(fmt::format("{}: '{}' is not a number", what, text));
    return *v;
}

void KlartextInterpreter::tool(const std::vector<std::string>& rest) {
    if (rest.empty()) fail("expected TOOL CALL or TOOL DEF");
    if (rest[0] == "DEF") return;
    if (rest[0] != "CALL") fail("expected TOOL CALL or TOOL DEF");
    size_t i = 1;
    int toolNo = -1;
    if (i < rest.size() && !rest[i].empty() && rest[i].front() == '"') {
        ++i;  // tool by name: its length comes from the default tool length
    } else if (i < rest.size() && std::isdigit(static_cast<unsigned char>(rest[i].front()))) {
        // A whole number in the range of the setup's tool lengths (Setup::addToolLength): a larger one would not
        // fit an int (found by the Klartext fuzz target, tests/test_fuzz_findings.cpp).
        const double n = number(rest[i], "TOOL CALL number");
        if (!(n >= 0 && n <= 100000 && n == std::floor(n)))
            fail(fmt::format("TOOL CALL number '{}' is not a tool number 0 … 100000", rest[i]));
        toolNo = static_cast<int>(n);
        ++i;
    }
    double dl = 0;
    int axis = toolAxis_;
    for (; i < rest.size(); ++i) {
        const std::string& t = rest[i];
        if (t.size() == 1 && L_.axis(t[0]) >= 0 && !L_.rotary[L_.axis(t[0])]) {
            axis = L_.axis(t[0]);
        } else if (t.rfind("DL", 0) == 0) {
            dl = number(t.substr(2), "TOOL CALL DL") * linScale();
        }  // S, F, DR, DR2: no effect on positions
    }
    double length = setup_.defaultToolLength;
    tip_ = setup_.defaultToolLength + dl;
    tipAssumed_ = !setup_.defaultToolLengthGiven;
    if (toolNo == 0) length = 0;
    else if (toolNo > 0)
        if (const auto l = setup_.toolLength(toolNo)) length = *l, tip_ = *l + dl, tipAssumed_ = false;
    if (mode_ != ProgramMode::Joints && (length + dl != tlo_ || axis != toolAxis_)) {
        // The manual asks to reset TCPM before a TOOL CALL; the tool tip moves with the new length.
        toolAxis_ = axis;
        tlo_ = length + dl;
        unsupported("TOOL CALL with TCPM active (the manual asks to reset M128 / FUNCTION TCPM first): linear positions "
                    "unknown until programmed",
                    2);
    }
    toolAxis_ = axis;
    tlo_ = length + dl;
    tangentKnown_ = false;
}

void KlartextInterpreter::mOnly(const std::vector<std::string>& rest, KlartextBlock& b) {
    bool on = false, off = false;
    for (const std::string& u : rest) {
        if (u.front() != 'M') fail(fmt::format("unexpected '{}' in a block without motion", u));
        const double m = number(std::string_view(u).substr(1), "M function");
        b.hasM = true;
        if (m == 99 || m == 89) unsupported("M99/M89 cycle calls are not evaluated by cnccomp's Klartext reader", 3);
        if (m == 140) unsupported("M140 (retract along the tool axis) is not evaluated by cnccomp's Klartext reader", 2);
        if (m == 128) on = true;
        if (m == 129) off = true;
    }
    if (on && mode_ == ProgramMode::Joints) switchTcp(ProgramMode::TcpAngles, b), b.modeSwitch = true;
    if (off && mode_ != ProgramMode::Joints) switchTcp(ProgramMode::Joints, b), b.modeSwitch = true;
}

void KlartextInterpreter::switchTcp(ProgramMode to, KlartextBlock&) {
    const AxisMask rotary = L_.rotaryAxes();
    if (convert_) known_ = convert_(mode_, to, tlo_, pos_, known_);
    else known_ &= rotary;
    mode_ = to;
    tangentKnown_ = false;
}

void KlartextInterpreter::function(const std::vector<std::string>& rest, KlartextBlock& b) {
    if (rest.size() >= 2 && rest[0] == "RESET" && rest[1] == "TCPM") {
        if (tcpUnsupportedLine_) {
            tcpUnsupportedLine_ = 0;
            unsupported("FUNCTION RESET TCPM after a FUNCTION TCPM that was not evaluated: positions unknown until programmed", 3);
        }
        if (mode_ != ProgramMode::Joints) switchTcp(ProgramMode::Joints, b), b.modeSwitch = true;
        return;
    }
    if (!rest.empty() && rest[0] == "TCPM") {
        // F TCP | F CONT (feed only), AXIS POS (rotary words are axis angles), PATHCTRL AXIS (the tool tip on a straight
        // line, the axes interpolated linearly), REFPNT TIP-TIP (the default): what is evaluated here.
        bool axisPos = false, pathAxis = false, other = false;
        for (size_t i = 1; i < rest.size(); ++i) {
            const std::string& t = rest[i];
            const std::string next = i + 1 < rest.size() ? rest[i + 1] : "";
            if (t == "F" && (next == "TCP" || next == "CONT")) ++i;
            else if (t == "AXIS" && next == "POS") axisPos = true, ++i;
            else if (t == "PATHCTRL" && next == "AXIS") pathAxis = true, ++i;
            else if (t == "REFPNT" && next == "TIP-TIP") ++i;
            else other = true;
        }
        if (!axisPos || !pathAxis || other) {
            tcpUnsupportedLine_ = line_;
            if (mode_ != ProgramMode::Joints) mode_ = ProgramMode::Joints;
            unsupported("FUNCTION TCPM without AXIS POS and PATHCTRL AXIS (or with AXIS SPAT, PATHCTRL VECTOR, REFPNT "
                        "other than TIP-TIP) is not evaluated by cnccomp's Klartext reader: every motion is passed "
                        "through until FUNCTION RESET TCPM",
                        3);
        }
        if (mode_ == ProgramMode::Joints) switchTcp(ProgramMode::TcpAngles, b), b.modeSwitch = true;
        return;
    }
    unsupported(fmt::format("FUNCTION {} is not evaluated by cnccomp's Klartext reader", rest.empty() ? "" : rest[0]), 3);
}

void KlartextInterpreter::plane(const std::vector<std::string>& rest) {
    if (!rest.empty() && rest[0] == "RESET") {
        const bool was = transformLine_ != 0;
        transformLine_ = 0;
        if (was) unsupported("PLANE RESET after a transformation that was not evaluated: positions unknown until programmed", 3);
        return;
    }
    transformLine_ = line_;
    unsupported("PLANE (tilted working plane) is not evaluated by cnccomp's Klartext reader", 3);
}

void KlartextInterpreter::cycle(const std::vector<std::string>& rest) {
    if (rest.empty()) fail("expected CYCL DEF or CYCL CALL");
    if (rest[0] == "CALL")
        unsupported("CYCL CALL: machining cycles are not evaluated by cnccomp's Klartext reader (their moves are not known)", 3);
    if (rest[0] != "DEF" || rest.size() < 2) fail("expected CYCL DEF <number>");
    const double id = number(rest[1], "cycle number");
    // A cycle number beyond any cycle would overflow the int below (fuzz finding, ReaderFuzz_klartext).
    if (!(id >= 0 && id < 100000)) fail("expected a cycle number from 0 to 99999");
    const int cycle = static_cast<int>(std::floor(id + 1e-9));
    const int sub = static_cast<int>(std::lround((id - cycle) * 10));
    if (cycle == 8 || cycle == 10 || cycle == 11 || cycle == 19 || cycle == 26 || cycle == 247) {
        transformLine_ = line_;
        unsupported(fmt::format("cycle {} (coordinate transformation) is not evaluated by cnccomp's Klartext reader", cycle), 0);
    }
    if (cycle != 7) return;  // dwell (9) and cycle definitions: no motion
    if (sub == 0) {
        shift_.setZero();
        return;
    }
    for (size_t i = 2; i < rest.size(); ++i) {
        const std::string& t = rest[i];
        if (t.front() == '#') unsupported("cycle 7 with a datum table line is not evaluated by cnccomp's Klartext reader", 3);
        const bool inc = t.front() == 'I' && t.size() > 2 && L_.axis(t[1]) >= 0 && klartextNumberStart(t[2]);
        const size_t p = inc ? 1 : 0;
        const int a = L_.axis(t[p]);
        if (a < 0 || t.size() <= p + 1) fail(fmt::format("cycle 7: '{}' is not an axis value", t));
        const double v = number(std::string_view(t).substr(p + 1), "datum shift") * unit(a);
        shift_[a] = inc ? shift_[a] + v : v;
    }
}

KlartextInterpreter::Words KlartextInterpreter::words(std::string_view text, KlartextBlock& b, bool allowPolar,
                                                      bool allowRadius) const {
    Words w;
    for (size_t i = static_cast<size_t>(b.keyToken) + 1; i < tok_.size(); ++i) {
        const std::string& t = tok_[i];
        const int ti = static_cast<int>(i);
        if (t == "R0" || t == "RL" || t == "RR" || t == "R") {  // radius compensation: positions as programmed
            b.radiusCompToken = ti;
            continue;
        }
        if (t == "FMAX") {
            w.rapid = true;
            continue;
        }
        if (t == "FAUTO" || t == "FU" || t == "FZ") continue;
        if (t.front() == 'F' && t.size() > 1 && klartextNumberStart(t[1])) {
            number(std::string_view(t).substr(1), "feed");
            continue;
        }
        if (t == "DR+" || t == "DR-") {
            w.dr = t[2] == '+' ? 1 : -1;
            b.dropTokens.push_back(ti);
            continue;
        }
        if (klartextIsMWord(t)) {
            const double m = number(std::string_view(t).substr(1), "M function");
            b.hasM = true;
            if (m == 91 || m == 92) w.machine = true;
            if (m == 128) w.m128 = true;
            if (m == 129) w.m129 = true;
            if (m == 99 || m == 89) unsupported("M99/M89 cycle calls are not evaluated by cnccomp's Klartext reader", 3);
            if (m == 140) unsupported("M140 (retract along the tool axis) is not evaluated by cnccomp's Klartext reader", 2);
            continue;
        }
        if (allowRadius && t.front() == 'R' && t.size() > 1 && klartextNumberStart(t[1])) {
            w.hasR = true;
            w.radius = number(std::string_view(t).substr(1), "radius R");
            b.dropTokens.push_back(ti);
            continue;
        }
        if (allowPolar) {
            const bool inc = t.front() == 'I';
            const std::string_view s = std::string_view(t).substr(inc ? 1 : 0);
            if (s.size() > 2 && (s.substr(0, 2) == "PR" || s.substr(0, 2) == "PA") && (klartextNumberStart(s[2]) || s[2] == 'Q')) {
                const double v = number(s.substr(2), s.substr(0, 2));
                if (s[1] == 'R') w.hasPR = true, w.incPR = inc, w.pr = v;
                else w.hasPA = true, w.incPA = inc, w.pa = v;
                b.dropTokens.push_back(ti);
                continue;
            }
        }
        const bool inc = t.front() == 'I' && t.size() > 2 && L_.axis(t[1]) >= 0;
        const size_t p = inc ? 1 : 0;
        const int a = L_.axis(t[p]);
        if (a >= 0 && t.size() > p + 1) {
            KlartextAxisWord aw;
            aw.axis = a;
            aw.incremental = inc;
            aw.value = number(std::string_view(t).substr(p + 1), std::string(1, t[p]));
            aw.token = ti;
            aw.numberBegin = b.tokens[i].begin + static_cast<uint32_t>(p + 1);
            w.axes.push_back(aw);
            continue;
        }
        fail(fmt::format("unexpected '{}'", text.substr(b.tokens[i].begin, b.tokens[i].end - b.tokens[i].begin)));
    }
    b.machine = w.machine;
    return w;
}

unsigned KlartextInterpreter::apply(const Words& w, KlartextBlock& b, AxisVector& end, unsigned& endKnown) const {
    unsigned set = 0;
    for (const KlartextAxisWord& aw : w.axes) {
        const int a = aw.axis;
        const unsigned bit = 1u << a;
        if (set & bit) fail(fmt::format("axis {} twice in one block", L_.letter[a]));
        set |= bit;
        const double v = aw.value * unit(a);
        if (aw.incremental) {
            end[a] += v;  // unknown stays unknown
        } else {
            const bool tipAxis = a == toolAxis_ && mode_ == ProgramMode::Joints;
            end[a] = w.machine ? v : v + shift_[a] + (tipAxis ? tlo_ : 0.0);
            endKnown |= bit;
        }
    }
    b.axes = w.axes;
    b.words = set;
    return set;
}

void KlartextInterpreter::moveMode(const Words& w, KlartextBlock& b) {
    // M128 acts from the start of its block, M129 at its end.
    if (w.m128 && mode_ == ProgramMode::Joints) {
        switchTcp(ProgramMode::TcpAngles, b);
        b.tcpOnAtStart = true;
    }
    if (w.machine && mode_ != ProgramMode::Joints)
        unsupported("M91/M92 with TCPM active (the manual asks to reset M128 / FUNCTION TCPM first)", 3);
    b.start = pos_;
    b.startKnown = known_;
    b.mode = mode_;
    b.controlLength = tlo_;
    b.tipLength = tip_;
    b.tipLengthAssumed = tipAssumed_;
    b.scale = AxisVector::Ones(L_.count);
    b.offset = AxisVector::Zero(L_.count);
    for (int a = 0; a < L_.count; ++a) {
        b.scale[a] = unit(a);
        b.offset[a] = w.machine ? 0.0 : shift_[a] + (a == toolAxis_ && mode_ == ProgramMode::Joints ? tlo_ : 0.0);
    }
}

void KlartextInterpreter::finishMove(KlartextBlock& b) {
    pos_ = b.end;
    known_ = b.endKnown;
}

void KlartextInterpreter::tangentOfLine(const AxisVector& from, const AxisVector& to, unsigned knownBoth) {
    Vec3 d = Vec3::Zero();
    bool ok = true;
    for (int c = 0; c < 3; ++c) {
        const int a = L_.axis("XYZ"[c]);
        if (a < 0) continue;
        if (!(knownBoth & (1u << a))) ok = false;
        else d[c] = to[a] - from[a];
    }
    if (ok && d.norm() > 1e-12) {
        tangent_ = d.normalized();
        tangentKnown_ = true;
    }
}

void KlartextInterpreter::linear(std::string_view text, KlartextBlock& b) {
    const Words w = words(text, b, false, false);
    if (w.dr != 0) fail("DR+/DR- in a straight block");
    moveMode(w, b);
    AxisVector end = pos_;
    unsigned endKnown = known_;
    const unsigned set = apply(w, b, end, endKnown);
    if (set) {
        b.kind = KlartextKind::Move;
        b.motion = w.rapid ? Motion::Rapid : Motion::Linear;
        b.end = end;
        b.endKnown = endKnown;
        tangentOfLine(pos_, end, known_ & endKnown);
        finishMove(b);
    } else if (b.tcpOnAtStart) {
        b.modeSwitch = true;  // L with only M / F words
    }
    if (w.m129 && mode_ != ProgramMode::Joints) {
        switchTcp(ProgramMode::Joints, b);
        if (set) b.tcpOffAtEnd = true;
        else b.modeSwitch = true;
    }
}

bool KlartextInterpreter::planeOf(int a, int b, int& a0, int& a1) const {
    const int X = L_.axis('X'), Y = L_.axis('Y'), Z = L_.axis('Z');
    const auto is = [&](int p, int q) { return (a == p && b == q) || (a == q && b == p); };
    if (X >= 0 && Y >= 0 && is(X, Y)) a0 = X, a1 = Y;
    else if (Y >= 0 && Z >= 0 && is(Y, Z)) a0 = Y, a1 = Z;
    else if (Z >= 0 && X >= 0 && is(Z, X)) a0 = Z, a1 = X;
    else return false;
    return true;
}

void KlartextInterpreter::workingPlane(int& a0, int& a1) const {
    const int X = L_.axis('X'), Y = L_.axis('Y'), Z = L_.axis('Z');
    if (toolAxis_ >= 0 && toolAxis_ == Y) a0 = Z, a1 = X;
    else if (toolAxis_ >= 0 && toolAxis_ == X) a0 = Y, a1 = Z;
    else a0 = X, a1 = Y;
    if (a0 < 0 || a1 < 0) fail("the working plane's axes are missing on this machine");
}

void KlartextInterpreter::pole(std::string_view text, KlartextBlock& b) {
    const Words w = words(text, b, false, false);
    if (w.dr || w.rapid || w.machine || w.m128 || w.m129) fail("CC takes the two coordinates of the circle centre only");
    if (w.axes.empty()) {
        workingPlane(poleA0_, poleA1_);
    } else {
        if (w.axes.size() != 2 || !planeOf(w.axes[0].axis, w.axes[1].axis, poleA0_, poleA1_))
            fail("CC needs two coordinates of one plane (X Y, Y Z or Z X)");
    }
    AxisVector c = pos_;
    unsigned ck = known_;
    apply(w, b, c, ck);  // b.axes: for the number style of the program
    const unsigned need = (1u << poleA0_) | (1u << poleA1_);
    poleKnown_ = (ck & need) == need;
    pc0_ = c[poleA0_];
    pc1_ = c[poleA1_];
}

void KlartextInterpreter::arcEnd(bool ccw, int a0, int a1, double c0, double c1, double sweep, bool centreKnown,
                                 const AxisVector& end, unsigned endKnown, KlartextBlock& b) {
    b.kind = KlartextKind::Move;
    b.motion = ccw ? Motion::ArcCcw : Motion::ArcCw;
    b.end = end;
    b.endKnown = endKnown;
    b.arcKnown = centreKnown;
    b.arc = ArcGeometry{};
    b.arc.axis0 = a0;
    b.arc.axis1 = a1;
    b.arc.c0 = c0;
    b.arc.c1 = c1;
    b.arc.sweep = sweep;
    for (int a = 0; a < L_.count; ++a)
        if (a != a0 && a != a1 && !L_.rotary[a] && b.arc.normal < 0) b.arc.normal = a;
    // End tangent, for a following CT.
    if (centreKnown) {
        const double r0 = end[a0] - c0, r1 = end[a1] - c1;
        Vec3 t = Vec3::Zero();
        const auto put = [&](int axis, double v) {
            for (int c = 0; c < 3; ++c)
                if (L_.axis("XYZ"[c]) == axis) t[c] = v;
        };
        put(a0, ccw ? -r1 : r1);
        put(a1, ccw ? r0 : -r0);
        if (t.norm() > 1e-12) tangent_ = t.normalized(), tangentKnown_ = true;
    } else {
        tangentKnown_ = false;
    }
    finishMove(b);
}

namespace {
/// Signed sweep from angle th0 to th1 in the given direction, in (0, 2π] (a full circle when they coincide).
double klartextSweep(double th0, double th1, bool ccw) {
    double s = th1 - th0;
    if (ccw) {
        while (s <= 1e-12) s += kTwoPi;
        while (s > kTwoPi + 1e-12) s -= kTwoPi;
    } else {
        while (s >= -1e-12) s -= kTwoPi;
        while (s < -kTwoPi - 1e-12) s += kTwoPi;
    }
    return s;
}
}  // namespace

void KlartextInterpreter::circle(const std::string& key, std::string_view text, KlartextBlock& b) {
    const Words w = words(text, b, false, key == "CR");
    if (w.rapid) fail(key + " with FMAX");
    moveMode(w, b);
    AxisVector end = pos_;
    unsigned endKnown = known_;
    int a0 = -1, a1 = -1;
    if (key == "C") {
        if (poleA0_ < 0) fail("C without a circle centre: program CC first");
        a0 = poleA0_, a1 = poleA1_;
    } else if (w.axes.size() == 2 && planeOf(w.axes[0].axis, w.axes[1].axis, a0, a1)) {
    } else {
        workingPlane(a0, a1);
    }
    for (const KlartextAxisWord& aw : w.axes)
        if (aw.axis != a0 && aw.axis != a1) fail(fmt::format("{}: axis {} is not in the plane of the circle", key, L_.letter[aw.axis]));
    apply(w, b, end, endKnown);
    const unsigned plane = (1u << a0) | (1u << a1);
    const bool startKnown = (known_ & plane) == plane;
    if (key == "C") {
        if (w.dr == 0) fail("C needs the direction of rotation DR+ or DR-");
        if (startKnown && poleKnown_) {
            const double rs = std::hypot(pos_[a0] - pc0_, pos_[a1] - pc1_), re = std::hypot(end[a0] - pc0_, end[a1] - pc1_);
            if (std::abs(rs - re) > 0.016)
                fail(fmt::format("C: the end point is {:.4f} mm off the circle through the start point about CC", std::abs(rs - re)));
        }
        const bool known = startKnown && poleKnown_ && (endKnown & plane) == plane;
        const double sweep = known ? klartextSweep(std::atan2(pos_[a1] - pc1_, pos_[a0] - pc0_),
                                                   std::atan2(end[a1] - pc1_, end[a0] - pc0_), w.dr > 0)
                                   : 0.0;
        return arcEnd(w.dr > 0, a0, a1, pc0_, pc1_, sweep, known, end, known ? endKnown : endKnown & ~plane, b);
    }
    if (key == "CT" && !tangentKnown_ && !forgotAny_) fail("CT needs a preceding contour element to be tangential to");
    if (!startKnown || (key == "CT" && !tangentKnown_) || (endKnown & plane) != plane)
        return arcEnd(w.dr > 0, a0, a1, 0, 0, 0, false, end, endKnown & ~plane, b);
    const double s0 = pos_[a0], s1 = pos_[a1], e0 = end[a0], e1 = end[a1];
    const double dx = e0 - s0, dy = e1 - s1, d = std::hypot(dx, dy);
    if (key == "CR") {
        if (!w.hasR) fail("CR needs the radius R+ or R-");
        if (w.dr == 0) fail("CR needs the direction of rotation DR+ or DR-");
        const double r = std::abs(w.radius) * linScale();
        if (!(r > 0) || d < 1e-9) fail("CR with zero radius or coincident end points");
        if (d / 2 > r * (1 + 1e-9) + 1e-6) fail("CR: the radius is smaller than half the distance to the end point");
        const double h = d / 2 >= r ? 0.0 : std::sqrt(r * r - d * d / 4);
        // Centre to the right of start→end for a clockwise arc of at most 180° (R+), to the left when counter-clockwise.
        double side = w.dr < 0 ? 1.0 : -1.0;
        if (w.radius < 0) side = -side;
        const double c0 = (s0 + e0) / 2 + side * h * dy / d, c1 = (s1 + e1) / 2 - side * h * dx / d;
        const double sweep = klartextSweep(std::atan2(s1 - c1, s0 - c0), std::atan2(e1 - c1, e0 - c0), w.dr > 0);
        return arcEnd(w.dr > 0, a0, a1, c0, c1, sweep, true, end, endKnown, b);
    }
    // CT: tangential to the previous contour element.
    double t0 = 0, t1 = 0;
    for (int c = 0; c < 3; ++c) {
        if (L_.axis("XYZ"[c]) == a0) t0 = tangent_[c];
        if (L_.axis("XYZ"[c]) == a1) t1 = tangent_[c];
    }
    const double tn = std::hypot(t0, t1);
    if (tn < 1e-9) fail("CT: the previous contour element does not move in the plane of the circle");
    t0 /= tn, t1 /= tn;
    const double n0 = -t1, n1 = t0;  // left normal
    const double dn = dx * n0 + dy * n1;
    if (std::abs(dn) < 1e-9 * std::max(1.0, d)) fail("CT: the end point lies on the tangent (no circle)");
    const double rho = (dx * dx + dy * dy) / (2 * dn);
    const double c0 = s0 + rho * n0, c1 = s1 + rho * n1;
    const double sweep = klartextSweep(std::atan2(s1 - c1, s0 - c0), std::atan2(e1 - c1, e0 - c0), rho > 0);
    arcEnd(rho > 0, a0, a1, c0, c1, sweep, true, end, endKnown, b);
}

void KlartextInterpreter::polarBlock(const std::string& key, std::string_view text, KlartextBlock& b) {
    const Words w = words(text, b, true, false);
    b.polar = true;
    if (poleA0_ < 0) fail(key + " without a pole: program CC first");
    moveMode(w, b);
    const int a0 = poleA0_, a1 = poleA1_;
    const unsigned plane = (1u << a0) | (1u << a1);
    for (const KlartextAxisWord& aw : w.axes)
        if (aw.axis == a0 || aw.axis == a1) fail(fmt::format("{}: axis {} of the pole's plane in a polar block", key, L_.letter[aw.axis]));
    AxisVector end = pos_;
    unsigned endKnown = known_;
    apply(w, b, end, endKnown);
    if (!poleKnown_ || (known_ & plane) != plane) {
        if (!forgotAny_)
            fail(poleKnown_ ? key + ": the start position in the plane of the pole is not known" : key + " without a pole: program CC first");
        // After a block that was not evaluated: the end in the plane is not known.
        if (key == "LP") {
            b.kind = KlartextKind::Move;
            b.motion = w.rapid ? Motion::Rapid : Motion::Linear;
            b.end = end;
            b.endKnown = endKnown & ~plane;
            return finishMove(b);
        }
        return arcEnd(w.dr > 0, a0, a1, 0, 0, 0, false, end, endKnown & ~plane, b);
    }
    const double r0 = std::hypot(pos_[a0] - pc0_, pos_[a1] - pc1_);
    const double ang0 = std::atan2(pos_[a1] - pc1_, pos_[a0] - pc0_);
    double r = r0, ang = ang0;
    if (key == "LP") {
        if (w.dr) fail("LP with DR+/DR-");
        if (w.hasPR) r = w.incPR ? r0 + w.pr * linScale() : w.pr * linScale();
    } else {
        if (w.hasPR) fail("CP takes no PR: the radius is the distance to the pole");
        if (w.dr == 0) fail("CP needs the direction of rotation DR+ or DR-");
    }
    if (w.hasPA) ang = w.incPA ? ang0 + w.pa * kDeg : w.pa * kDeg;
    if (!(r >= 0)) fail(key + ": negative polar radius");
    end[a0] = pc0_ + r * std::cos(ang);
    end[a1] = pc1_ + r * std::sin(ang);
    endKnown |= plane;
    if (key == "LP") {
        b.kind = KlartextKind::Move;
        b.motion = w.rapid ? Motion::Rapid : Motion::Linear;
        b.end = end;
        b.endKnown = endKnown;
        tangentOfLine(pos_, end, known_ & endKnown);
        return finishMove(b);
    }
    // CP: an incremental angle keeps its turns (helix); an absolute one is reached the shortest way in DR's sense.
    const double sweep = w.hasPA && w.incPA ? w.pa * kDeg : klartextSweep(ang0, ang, w.dr > 0);
    arcEnd(w.dr > 0, a0, a1, pc0_, pc1_, sweep, true, end, endKnown, b);
}

}  // namespace cnccomp::postproc
