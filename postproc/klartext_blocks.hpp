#pragma once
// HEIDENHAIN conversational (Klartext) blocks: the tokenizer and the modal interpreter shared by `cnccomp poses`
// (postproc/klartext_reader.*) and `cnccomp correct` (postproc/klartext_correct.*). Sources: HEIDENHAIN TNC 640
// user's manual for Klartext programming (ID 1303406), chapters "Programming contours" (L, CC, C, CR, CT, LP, CP) and
// "Cycles: coordinate transformations" (cycle 7 DATUM SHIFT), "Special cycles" (cycle 9 DWELL TIME); HEIDENHAIN iTNC 530
// user's manual (conversational, 340 49x-06), chapter 12 "Programming: Multiple Axis Machining": 12.4 "TCPM FUNCTION"
// (F TCP / F CONT, AXIS POS / AXIS SPAT, PATHCTRL AXIS / PATHCTRL VECTOR, FUNCTION RESET TCPM) and 12.6 "Maintaining the
// position of the tool tip when positioning with tilted axes (TCPM): M128" (the tool length refers to the tool tip; on
// tilting tables the coordinates turn with the table; reset M128 before M91/M92 and TOOL CALL).
//
// Read: BEGIN/END PGM (MM, INCH), BLK FORM and TOOL DEF (no motion), TOOL CALL (tool axis = working plane; the tool's
// length from the setup plus DL shifts the tool axis, as G43 does), L with absolute or incremental (IX) words, R0/RL/RR,
// F/FMAX/FAUTO (FMAX = rapid, this block only), M words (M91/M92: machine coordinates, like G53), CC (pole, absolute or
// incremental, none = current position), C with DR+/DR− (DR+ counter-clockwise seen from the + side of the plane
// normal; the plane is given by the two axes of CC [G] for ZX/YZ), CR with R± (+: at most 180°), CT (tangential
// continuation of the previous contour element), LP/CP (polar, PR/PA/IPR/IPA, CP with an incremental tool-axis word for
// a helix), STOP, CYCL DEF 7 (datum shift, absolute or incremental values), CYCL DEF 9 (dwell), other CYCL DEF
// (definitions without motion), ';' comments and '*' structure lines, '~' continuation lines.
// Tool-tip (TCP) mode: M128 (on from the start of its block) / M129 (off at the end of its block) [G: the iTNC 530
// manual's "Effect" paragraph of M128 as quoted by secondary copies], FUNCTION TCPM F TCP|F CONT AXIS POS PATHCTRL AXIS
// [REFPNT TIP-TIP] (on) / FUNCTION RESET TCPM (off). In TCP mode positions are the tool tip (at the called tool's length
// + DL) in the workpiece frame with the datum shift, and the rotary axis angles (AXIS POS): program space of
// postproc/tcp_model.hpp. Outside TCP mode positions are machine coordinates (preset at the machine datum [G]).
//
// Malformed input (a number that is not one, a word that is not one, a circle that cannot be) throws InputError
// naming the file and line. What is valid Klartext but not evaluated here is returned as KlartextKind::Unsupported
// with the reason, and the interpreter forgets what it may change: LBL / CALL LBL / CALL PGM (every position), CYCL
// CALL, M99/M89 (every position), M140, APPR/DEP, FK, SPL (the linear positions), LN (its axes), Q parameters in
// words (the axes of the block), Q / FN assignments and RND/CHF (nothing), PLANE, TRANS and the transformation
// cycles 8, 10, 11, 19, 26, 247 (every later motion block is unsupported until PLANE RESET), FUNCTION TCPM with AXIS
// SPAT, PATHCTRL VECTOR or another REFPNT (every motion until FUNCTION RESET TCPM), and any other keyword (every
// position). `cnccomp poses` refuses them (InputError); `cnccomp correct` passes them through and reports them.
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "postproc/modal.hpp"

namespace cnccomp::postproc {

/// A byte span of a block's text.
struct KlartextToken {
    uint32_t begin = 0, end = 0;
};

/// Code tokens of a logical block (its physical lines joined with their line ends): for each physical line the part
/// before ';' without a trailing '~', split at white space; a quoted name ("...") stays one token.
void tokenizeKlartext(std::string_view block, std::vector<KlartextToken>& tokens);

/// An axis word of a path block.
struct KlartextAxisWord {
    int axis = -1;
    bool incremental = false;
    double value = 0;           ///< as written (mm / inch / deg)
    int token = -1;             ///< token index
    uint32_t numberBegin = 0;   ///< byte of the number (after the letter, and the I of an incremental word)
};

enum class KlartextKind : uint8_t {
    Empty,        ///< blank, comment or structure line
    NoMotion,     ///< evaluated, no motion (BEGIN PGM, TOOL CALL, CC, cycle definitions, M functions, TCPM switches)
    Move,         ///< L, LP, C, CR, CT, CP (also with an unknown axis: see endKnown)
    Unsupported,  ///< valid Klartext that is not evaluated: `reason`; the interpreter has forgotten what it may change
};

struct KlartextBlock {
    std::vector<KlartextToken> tokens;
    int numberToken = -1;               ///< the leading block number
    int keyToken = -1;                  ///< the keyword (L, C, TOOL …)
    KlartextKind kind = KlartextKind::Empty;
    Motion motion = Motion::Unknown;    ///< Move: Rapid (FMAX), Linear (L, LP), ArcCw / ArcCcw (DR− / DR+)
    bool polar = false;                 ///< LP / CP
    bool machine = false;               ///< M91 / M92: machine coordinates
    bool hasM = false;                  ///< the block holds an M function
    bool arcKnown = false;              ///< arcs: start and centre known (`arc` is valid)
    AxisVector start, end;              ///< program space before / after (see the file header)
    AxisMask startKnown = 0, endKnown = 0, words = 0;
    std::vector<KlartextAxisWord> axes; ///< axis words in block order
    std::vector<int> dropTokens;        ///< tokens that make the block a circle or a polar line (PR PA IPR IPA DR± CR's R)
    int radiusCompToken = -1;           ///< R0 / RL / RR
    ArcGeometry arc;                    ///< arcs: plane, centre and signed sweep in program space
    ProgramMode mode = ProgramMode::Joints;  ///< how the motion's positions are read
    double controlLength = 0.0;         ///< mm: the called tool's length + DL (TCP: the programmed point is its tip)
    double tipLength = 0.0;             ///< mm: the physical tool point to correct: the called tool's length + DL from
                                        ///< the setup, or the setup's default length (+ DL) for TOOL CALL 0, a tool
                                        ///< the setup does not list, or before any TOOL CALL
    bool tipLengthAssumed = false;      ///< tipLength is (+ DL) the default length that nobody gave
    AxisVector scale, offset;           ///< Move: program space = word · scale + offset for an absolute word
    bool tcpOnAtStart = false;          ///< M128 in this block switched TCP on before its motion
    bool tcpOffAtEnd = false;           ///< M129 in this block switched TCP off after its motion
    bool modeSwitch = false;            ///< a block without motion that switched the mode (FUNCTION TCPM, M128 / M129 alone)
    std::string reason;                 ///< Unsupported: why
};

/// Converts a program-space position from one mode to the other at a TCP switch (the machine stays where it is);
/// returns the axes known afterwards. Without a converter the rotary angles stay known and the linear axes become
/// unknown until the program names them.
using KlartextConvert = std::function<AxisMask(ProgramMode from, ProgramMode to, double controlLength, AxisVector& pos,
                                               AxisMask known)>;

class KlartextInterpreter {
public:
    KlartextInterpreter(const AxisLayout& layout, const Setup& setup, std::string inputName);

    void setConverter(KlartextConvert convert) { convert_ = std::move(convert); }
    /// Interprets one logical block `text` (its first physical line is `line`). Throws InputError when malformed.
    void interpret(std::string_view text, uint64_t line, KlartextBlock& b);

    bool ended() const { return ended_; }
    bool inch() const { return inch_; }
    ProgramMode mode() const { return mode_; }
    double controlLength() const { return tlo_; }
    const AxisVector& position() const { return pos_; }
    AxisMask known() const { return known_; }
    const AxisLayout& layout() const { return L_; }
    /// Everything unknown (a line that could not be read).
    void forgetAll() {
        known_ = 0;
        poleKnown_ = tangentKnown_ = false;
        forgotAny_ = true;
    }

private:
    struct Words;
    struct Unsupported {
        std::string reason;
        int forget;  ///< 0 nothing, 1 the block's axes, 2 the linear axes, 3 everything
    };
    [[noreturn]] void fail(const std::string& what) const;
    [[noreturn]] static void unsupported(std::string reason, int forget) { throw Unsupported{std::move(reason), forget}; }
    void dispatch(std::string_view text, KlartextBlock& b);
    void forget(const Unsupported& u, std::string_view text, KlartextBlock& b);
    double linScale() const { return inch_ ? 25.4 : 1.0; }
    double unit(int a) const { return L_.rotary[a] ? kDeg : linScale(); }
    double number(std::string_view text, std::string_view what) const;
    void begin(const std::vector<std::string>& rest);
    void tool(const std::vector<std::string>& rest);
    void mOnly(const std::vector<std::string>& rest, KlartextBlock& b);
    void cycle(const std::vector<std::string>& rest);
    void function(const std::vector<std::string>& rest, KlartextBlock& b);
    void plane(const std::vector<std::string>& rest);
    Words words(std::string_view text, KlartextBlock& b, bool allowPolar, bool allowRadius) const;
    unsigned apply(const Words& w, KlartextBlock& b, AxisVector& end, unsigned& endKnown) const;
    void switchTcp(ProgramMode to, KlartextBlock& b);
    void moveMode(const Words& w, KlartextBlock& b);
    void finishMove(KlartextBlock& b);
    void tangentOfLine(const AxisVector& from, const AxisVector& to, unsigned knownBoth);
    bool planeOf(int a, int b, int& a0, int& a1) const;
    void workingPlane(int& a0, int& a1) const;
    void linear(std::string_view text, KlartextBlock& b);
    void pole(std::string_view text, KlartextBlock& b);
    void arcEnd(bool ccw, int a0, int a1, double c0, double c1, double sweep, bool centreKnown, const AxisVector& end,
                unsigned endKnown, KlartextBlock& b);
    void circle(const std::string& key, std::string_view text, KlartextBlock& b);
    void polarBlock(const std::string& key, std::string_view text, KlartextBlock& b);

    const AxisLayout& L_;
    const Setup& setup_;
    std::string inputName_;
    KlartextConvert convert_;
    uint64_t line_ = 0;
    bool inch_ = false, ended_ = false;
    AxisVector pos_, shift_;
    unsigned known_ = 0;
    int toolAxis_ = -1;
    double tlo_ = 0;
    double tip_ = 0;
    bool tipAssumed_ = false;  ///< tip_ is the default length that nobody gave (Setup::defaultToolLengthGiven)
    int poleA0_ = -1, poleA1_ = -1;
    double pc0_ = 0, pc1_ = 0;
    bool poleKnown_ = false;
    Vec3 tangent_ = Vec3::Zero();
    bool tangentKnown_ = false;
    bool forgotAny_ = false;        ///< a block was not evaluated: later gaps are unknown positions, not errors
    ProgramMode mode_ = ProgramMode::Joints;
    uint64_t transformLine_ = 0;   ///< line of an active PLANE / TRANS / transformation cycle, 0 none
    uint64_t tcpUnsupportedLine_ = 0;  ///< line of an active FUNCTION TCPM this reader cannot follow, 0 none
    std::vector<std::string> tok_;     ///< upper-case tokens of the current block (reused)
};

/// Parses a leading block number token ("12"); false when the token is not all digits.
bool klartextBlockNumber(std::string_view token, uint64_t& number);

}  // namespace cnccomp::postproc
