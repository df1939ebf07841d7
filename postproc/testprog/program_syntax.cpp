#include "postproc/testprog/program_syntax.hpp"

#include <cctype>
#include <cmath>

#include <fmt/format.h>

#include "cnccomp/error.hpp"

namespace cnccomp::postproc::testprog {

const char* programExtension(postproc::Dialect d) {
    switch (d) {
        case postproc::Dialect::Rs274ngc: return ".ngc";
        case postproc::Dialect::Fanuc: return ".nc";
        case postproc::Dialect::Sinumerik: return ".mpf";
        case postproc::Dialect::Heidenhain: return ".h";
        case postproc::Dialect::Printer: break;
    }
    return ".nc";
}

std::string ProgramSyntax::number(double v, bool plus) const {
    // Fixed digits (no trimming): `cnccomp correct` keeps a word's decimals, so every word carries the full resolution.
    std::string s = fmt::format("{:.{}f}", v, decimals_);
    if (s.find('.') == std::string::npos) s.push_back('.');
    if (s.find_first_not_of("-0.") == std::string::npos && s.front() == '-') s.erase(s.begin());
    if (plus && s.front() != '-') s.insert(s.begin(), '+');
    return s;
}

std::string ProgramSyntax::plain(double v) {
    std::string s = fmt::format("{:.3f}", v);
    while (s.back() == '0') s.pop_back();
    if (s.back() == '.') s.pop_back();
    return s == "-0" ? "0" : s;
}

std::string ProgramSyntax::axisWords(const AxisVector& p, unsigned mask, bool plus) const {
    static constexpr std::string_view kOrder = "XYZUVWABC";
    std::string out;
    const auto word = [&](int a) {
        const bool rotary = machine_.axisLink(a).kind == AxisKind::Rotary;
        if (!out.empty()) out += ' ';
        const double shift = machine_.axisNames[a] == "Z" ? zShift_ : 0.0;
        out += machine_.axisNames[a] + number(rotary ? p[a] / kDeg : p[a] - shift, plus);
    };
    for (char c : kOrder) {
        const int a = machine_.axisIndex(std::string(1, c));
        if (a >= 0 && (mask & (1u << a))) word(a);
    }
    for (int a = 0; a < machine_.axisCount(); ++a)
        if ((mask & (1u << a)) && kOrder.find(machine_.axisNames[a].front()) == std::string_view::npos) word(a);
    return out;
}

std::string ProgramSyntax::clean(std::string_view text, bool parentheses, bool upper) {
    std::string s;
    for (char c : text) {
        if (parentheses && c == '(') c = '[';
        if (parentheses && c == ')') c = ']';
        if (c == '\n' || c == '\r' || c == ';') c = ' ';
        if (upper) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
        s.push_back(c);
    }
    return s;
}

namespace {

/// The ISO (DIN 66025) family: every code block numbered N1, N2, …; I/J/K incremental arc centres.
class IsoSyntax : public ProgramSyntax {
public:
    IsoSyntax(postproc::Dialect d, const MachineModel& m, int decimals) : ProgramSyntax(m, decimals), d_(d) {}

    void begin(const std::string& name, int number) override {
        if (d_ == postproc::Dialect::Fanuc) {
            emit("%");
            emit(fmt::format("O{:04d} ({})", number, clean(name, true, true)));
        }
    }
    void comment(std::string_view text) override {
        switch (d_) {
            case postproc::Dialect::Rs274ngc: emit(fmt::format("({})", clean(text, true, false))); break;
            case postproc::Dialect::Fanuc: emit(fmt::format("({})", clean(text, true, true))); break;
            default: emit(fmt::format("; {}", clean(text, false, false))); break;
        }
    }
    void init() override {
        const std::string datum = fmt::format(" {}", axisWords(AxisVector::Zero(machine_.axisCount()), allAxes(), false));
        switch (d_) {
            case postproc::Dialect::Rs274ngc:
                block("G17 G21 G40 G49 G80 G90 G94");
                block("G91.1 G61");                 // arc centres incremental; exact path (no blending)
                block("G10 L2 P1" + datum);          // G54 = machine coordinates
                block("G54");
                if (toolLength_ != 0) {
                    block("G43.1 Z" + number(toolLength_));  // LinuxCNC G-code reference, G43.1: dynamic tool length
                    zShift_ = toolLength_;
                }
                break;
            case postproc::Dialect::Fanuc:
                block("G17 G21 G40 G49 G80 G90 G94");
                block("G10 L2 P1" + datum);          // G54 = machine coordinates (programmable data input)
                block("G54");
                break;
            default:
                block("G17 G71 G40 G90 G94 D0");     // metric, no tool offset
                block("G500");                       // settable zero offsets off: base frame only
                break;
        }
        plane_ = 17;
    }
    void rapid(const AxisVector& p, unsigned mask) override {
        block("G0 " + axisWords(p, mask, false));
        track(p, mask);
    }
    void line(const AxisVector& p, double feed) override {
        block("G1 " + axisWords(p, allAxes(), false) + feedWord(feed));
        track(p, allAxes());
    }
    void arc(const AxisVector& p, const ArcBlock& a, double feed) override {
        std::string s;
        if (a.plane != plane_) {
            s = fmt::format("G{} ", a.plane);
            plane_ = a.plane;
        }
        s += a.ccw ? "G3 " : "G2 ";
        s += axisWords(p, allAxes(), false);
        // I, J, K: centre − start along X, Y, Z.
        const int X = machine_.axisIndex("X"), Y = machine_.axisIndex("Y"), Z = machine_.axisIndex("Z");
        const auto offset = [&](int axis) { return axis == a.axis0 ? a.c0 - pos_[axis] : a.c1 - pos_[axis]; };
        const auto inPlane = [&](int axis) { return axis >= 0 && (axis == a.axis0 || axis == a.axis1); };
        if (inPlane(X)) s += " I" + number(offset(X));
        if (inPlane(Y)) s += " J" + number(offset(Y));
        if (inPlane(Z)) s += " K" + number(offset(Z));
        block(s + feedWord(feed));
        track(p, allAxes());
    }
    bool arcsWithRotaryAxes() const override { return true; }
    bool passToolLength(double length) override {
        if (d_ != postproc::Dialect::Rs274ngc || length == 0 || machine_.axisIndex("Z") < 0 ||
            machine_.axisLink(machine_.axisIndex("Z")).kind != AxisKind::Linear)
            return false;
        toolLength_ = length;
        return true;
    }
    void dwell(double seconds) override {
        switch (d_) {
            case postproc::Dialect::Rs274ngc: block("G4 P" + plain(seconds)); break;
            case postproc::Dialect::Fanuc: block(fmt::format("G4 P{}", static_cast<long>(std::lround(seconds * 1000)))); break;
            default: block("G4 F" + plain(seconds)); break;
        }
    }
    void stop(std::string_view message) override {
        switch (d_) {
            case postproc::Dialect::Rs274ngc:
                emit("(MSG, " + clean(message, true, false) + ")");
                block("M0");
                break;
            case postproc::Dialect::Fanuc: block("M0 (" + clean(message, true, true) + ")"); break;
            default: block("M0 ; " + clean(message, false, false)); break;
        }
    }
    void end() override {
        if (zShift_ != 0) block("G49");
        block("M30");
        if (d_ == postproc::Dialect::Fanuc) emit("%");
    }
    std::vector<std::string> unconfirmed() const override {
        switch (d_) {
            case postproc::Dialect::Rs274ngc: return {};
            case postproc::Dialect::Fanuc:
                return {"[G] circular blocks carry the rotary axes as additional helical axes (helical interpolation B)",
                        "[G] G10 L2 P1 needs programmable data input; six decimals need increment system IS-C or finer"};
            default:
                return {"[G] circular blocks carry the rotary axes as additional axes interpolated with the circle",
                        "[G] G500 leaves the base frame active: it must be zero"};
        }
    }

private:
    void block(const std::string& code) { emit(fmt::format("N{} {}", ++n_, code)); }
    std::string feedWord(double f) {
        if (f == lastFeed_) return "";
        lastFeed_ = f;
        return " F" + plain(f);
    }
    void track(const AxisVector& p, unsigned mask) {
        if (pos_.size() != p.size()) pos_ = AxisVector::Zero(p.size());
        for (int a = 0; a < p.size(); ++a)
            if (mask & (1u << a)) pos_[a] = p[a];
    }

    postproc::Dialect d_;
    long n_ = 0;
    int plane_ = 17;
    double toolLength_ = 0;  ///< passToolLength's L; zShift_ takes it only once G43.1 is written (init's G10 datum
                             ///< line, written before it, is in unshifted machine coordinates)
    double lastFeed_ = -1;
    AxisVector pos_;
};

/// HEIDENHAIN conversational programming: numbered blocks from 0, ';' comments, L/CC/C path functions.
class KlartextSyntax : public ProgramSyntax {
public:
    KlartextSyntax(const MachineModel& m, int decimals) : ProgramSyntax(m, decimals) {}

    void begin(const std::string& name, int) override {
        name_ = clean(name, false, true);
        for (char& c : name_)
            if (c == ' ') c = '_';
        block("BEGIN PGM " + name_ + " MM");
    }
    void comment(std::string_view text) override { block("; " + clean(text, false, false)); }
    void init() override {
        block("TOOL CALL 0 Z");  // tool 0: length 0, radius 0; working plane XY
        block("CYCL DEF 7.0 DATUM SHIFT");
        int k = 1;
        for (int a = 0; a < machine_.axisCount() && k <= 6; ++a, ++k)
            block(fmt::format("CYCL DEF 7.{} {}{}", k, machine_.axisNames[a], number(0.0, true)));
    }
    void rapid(const AxisVector& p, unsigned mask) override { block("L " + axisWords(p, mask, true) + " R0 FMAX"); }
    void line(const AxisVector& p, double feed) override {
        block("L " + axisWords(p, allAxes(), true) + " R0" + feedWord(feed));
    }
    void arc(const AxisVector& p, const ArcBlock& a, double feed) override {
        const std::string n0 = machine_.axisNames[a.axis0], n1 = machine_.axisNames[a.axis1];
        if (a.c0 != cc0_ || a.c1 != cc1_ || a.axis0 != ccAxis0_) {
            block(fmt::format("CC {}{} {}{}", n0, number(a.c0, true), n1, number(a.c1, true)));
            cc0_ = a.c0, cc1_ = a.c1, ccAxis0_ = a.axis0;
        }
        block(fmt::format("C {}{} {}{} DR{} R0{}", n0, number(p[a.axis0], true), n1, number(p[a.axis1], true),
                          a.ccw ? "+" : "-", feedWord(feed)));
    }
    bool arcsWithRotaryAxes() const override { return false; }
    void dwell(double seconds) override {
        block("CYCL DEF 9.0 DWELL TIME");
        block("CYCL DEF 9.1 DWELL " + plain(seconds));
    }
    void stop(std::string_view message) override {
        comment(message);
        block("STOP");
    }
    void end() override { block("END PGM " + name_ + " MM"); }
    std::vector<std::string> unconfirmed() const override {
        return {"[G] circles in the ZX and YZ planes are given by the two axes of CC (not the working plane of TOOL CALL)",
                "[G] C blocks carry no rotary axis: where a rotary axis turns, the sweep is written as straight L blocks"
                " between the samples (chords)",
                "[G] the program runs with the preset at the machine datum: CYCL DEF 7 resets the datum shift only",
                "[G] positions with more than four decimals may need a finer display step (MP display resolution)"};
    }

private:
    void block(const std::string& code) { emit(fmt::format("{} {}", n_++, code)); }
    std::string feedWord(double f) {
        if (f == lastFeed_) return "";
        lastFeed_ = f;
        return " F" + plain(f);
    }

    std::string name_;
    long n_ = 0;
    double lastFeed_ = -1;
    double cc0_ = NAN, cc1_ = NAN;
    int ccAxis0_ = -1;
};

}  // namespace

std::unique_ptr<ProgramSyntax> ProgramSyntax::make(postproc::Dialect d, const MachineModel& machine, int decimals) {
    if (decimals < 0 || decimals > 9) throw ModelError(fmt::format("decimals must be between 0 and 9, not {}", decimals));
    if (d == postproc::Dialect::Printer)
        throw ModelError(fmt::format("test programs are written in {}, not for a printer",
                                     postproc::dialectNames(postproc::DialectUse::Write)));
    if (d == postproc::Dialect::Heidenhain) return std::make_unique<KlartextSyntax>(machine, decimals);
    return std::make_unique<IsoSyntax>(d, machine, decimals);
}

}  // namespace cnccomp::postproc::testprog
