#pragma once
// Modal state of a controller and the interpretation of one lexed block: which motion it commands, from
// where to where in machine coordinates (mm, rad), or why it cannot be evaluated. Follows the RS274NGC
// order of execution (feed mode, feed, tool, plane, units, tool length, work offset, distance modes,
// non-modal codes, motion) and the dialect differences listed in README (Fanuc increments, Sinumerik
// keywords, printer G0 = feed move).
#include <array>
#include <string_view>
#include <cstdint>
#include <utility>
#include <vector>

#include "cnccomp/machine.hpp"
#include "postproc/lexer.hpp"
#include "postproc/setup.hpp"

namespace cnccomp::postproc {

using AxisMask = uint32_t;
struct BlockWords;  // postproc/interp_read.hpp
struct GCodes;      // postproc/interp_check.hpp
struct Refusal;     // postproc/interp_check.hpp

/// Which program letter drives which machine axis, and how.
struct AxisLayout {
    int count = 0;
    std::array<char, kMaxAxes> letter{};
    std::array<bool, kMaxAxes> rotary{};
    std::array<bool, kMaxAxes> modulo{};
    std::array<int8_t, 26> ofLetter{};  ///< machine axis of a letter, -1 if none
    int zAxis = -1;                     ///< axis that G43 tool length offsets shift

    /// Axes of a machine; each axis name must be one letter. Throws ModelError otherwise.
    static AxisLayout fromMachine(const MachineModel& m);
    /// X Y Z (linear) A B C (rotary): for reading a program without a machine.
    static AxisLayout generic();
    int axis(char upperLetter) const {
        return upperLetter >= 'A' && upperLetter <= 'Z' ? ofLetter[upperLetter - 'A'] : -1;
    }
    AxisMask all() const { return count >= 32 ? ~0u : ((1u << count) - 1u); }
    /// The rotary axes (bit a: axis a).
    AxisMask rotaryAxes() const {
        AxisMask m = 0;
        for (int a = 0; a < count; ++a)
            if (rotary[a]) m |= 1u << a;
        return m;
    }
};

enum class Motion : uint8_t { Unknown, Rapid, Linear, ArcCw, ArcCcw, Cycle, Other };

/// How the controller reads a block's positions: machine coordinates (joints), or in tool-centre-point (TCP) mode the
/// tool point in its world frame with the orientation as rotary angles or as a tool vector (postproc/tcp_model.hpp).
enum class ProgramMode : uint8_t { Joints, TcpAngles, TcpVector };
/// Which tool-centre-point function a TCP mode came from (how the vector is written, how it was switched on).
enum class TcpSource : uint8_t { None, FanucAngles, FanucVector, Sinumerik, UserSwitch };
enum class FeedMode : uint8_t { PerMinute, InverseTime, PerRevolution };

struct ArcGeometry {
    int axis0 = -1, axis1 = -1;  ///< machine axes of the plane: (X,Y) G17, (Z,X) G18, (Y,Z) G19
    int normal = -1;             ///< machine axis along the plane normal (helix), -1 when the machine has none
    double c0 = 0, c1 = 0;       ///< centre, machine coordinates (mm)
    double sweep = 0;            ///< signed swept angle (rad), negative for G2 (clockwise seen from +normal)
    int turns = 1;               ///< RS274NGC P word
    bool radiusForm = false;     ///< R word (else I J K)
};

enum class BlockKind : uint8_t {
    Empty,        ///< blank, comment-only, % line
    NoMotion,     ///< evaluated, no axis motion (modal codes, M/S/T words, offsets …)
    Move,         ///< evaluated G0/G1/G2/G3 move with every machine axis known
    PassThrough,  ///< cannot be evaluated (or deliberately not corrected): written unchanged
};

enum class Warning : uint8_t {
    OffsetNotGiven,      ///< code = offset code: a work offset used that the setup does not give (taken as zero)
    ToolLengthNotGiven,  ///< code = H number: G43 with a register the setup does not give (default length used)
    UnitsAssumed,        ///< program sets neither G20 nor G21 before its first move
    RotaryAssumed,       ///< code = axis: an axis never commanded, taken at its assumed position (rotary: 0)
    CutterCompensation,  ///< G41/G42: corrections are computed on the programmed contour
    NoToolLengthAxis,    ///< G43 on a machine without a Z axis
};

struct BlockResult {
    BlockKind kind = BlockKind::Empty;
    Motion motion = Motion::Unknown;  ///< Move: Rapid / Linear / ArcCw / ArcCcw; PassThrough: the modal motion
    int motionWord = -1;              ///< index of the block's motion G word, -1 when modal
    bool motionCode = false;          ///< the block holds a motion G word (a motion code, even if not evaluated)
    AxisVector start, end;            ///< nominal machine positions before / after (mm, rad)
    AxisMask startKnown = 0;          ///< axes whose start position is known
    AxisMask endKnown = 0;            ///< axes whose end position is known
    AxisMask words = 0;               ///< machine axes with a word in this block
    std::array<int8_t, kMaxAxes> axisWord{};  ///< word index per machine axis, -1 none
    ArcGeometry arc;
    FeedMode feedMode = FeedMode::PerMinute;
    double feed = 0.0;                ///< F in effect (program units)
    int feedWord = -1;                ///< index of the block's F word
    double tipLength = 0.0;           ///< mm: active tool length (tool point along the tool direction)
    bool tipLengthAssumed = false;    ///< tipLength is the default length that nobody gave (Setup::defaultToolLengthGiven)
    ProgramMode mode = ProgramMode::Joints;  ///< how this block's positions are read (start and end)
    TcpSource tcpSource = TcpSource::None;
    double controlLength = 0.0;       ///< mm, TCP: the controller's tool length (the programmed point is there)
    bool modeSwitch = false;          ///< the TCP mode changes with this block (after its motion); `mode` is the new one
    std::array<int8_t, 3> vectorWord{{-1, -1, -1}};  ///< TcpVector: word of each vector component (I J K / A3 B3 C3)
    bool vectorGiven = false;         ///< TcpVector: the block programs the tool vector (else it is kept)
    std::array<double, 3> vector{};   ///< TcpVector: programmed vector (world, tip → spindle as written; not unit)
    bool stop = false;                ///< M0 M1 M2 M30 M60: the block's motion is not split
    bool rapidIsFeed = false;         ///< printers: G0 is a straight feed move
    bool absolute = true;
    bool arcAbsolute = false;
    bool inch = false;
    AxisVector scale;                 ///< machine units per program unit, per axis (25.4, kDeg, ½ for diameters …)
    AxisVector offset;                ///< machine = word · scale + offset (absolute words)
    AxisMask wrap = 0;                ///< modulo axes read as shortest-path positions in [0, 360)
    double increment = 0.001;         ///< Fanuc: value of one unit of an integer dimension word (program units)
    bool integerIncrements = false;   ///< Fanuc: dimension words without a point are in increments
    // PassThrough:
    const char* reason = nullptr;     ///< why (static string)
    int reasonCode = 0;               ///< detail: G code × 10, or 0
    char reasonLetter = 0;            ///< detail: the axis letter concerned, or 0
    bool machineCoordinates = false;  ///< G53 / SUPA move: words are machine coordinates
    bool report = true;               ///< list it in the pass-through report (false: ordinary uncorrected moves)
    // Warnings raised by this block (once per program and kind/code).
    std::array<std::pair<Warning, int>, 4> warnings{};
    int warningCount = 0;
};

struct InterpreterOptions {
    Dialect dialect = Dialect::Rs274ngc;
    Setup setup;
    bool rotaryShortest = false;  ///< modulo rotary axes: absolute positions in [0, 360) reached the shortest way
    int tcpOnM = -1;              ///< M code that switches tool-tip programming (angles) on, e.g. 428; -1 none
    int tcpOffM = -1;             ///< M code that switches it off, e.g. 429
};

class Interpreter {
public:
    Interpreter(const AxisLayout& layout, const InterpreterOptions& options);

    /// Interprets one block (`line` is the text the block was lexed from) and advances the modal state and
    /// the nominal position.
    void interpret(std::string_view line, const LexedBlock& block, BlockResult& result);
    /// A line the caller could not lex (overlong): everything becomes unknown.
    void forgetAll(BlockResult& result, const char* reason);
    /// A line the caller could not lex because it is longer than its buffer (gathered in `line`): the axes it names
    /// become unknown; when it holds G/M/O … codes or anything but plain words, every position and the motion mode
    /// do. Returns true in that second case. Comment-only lines change nothing (call only when line.code).
    bool forgetOverlong(const OverlongLine& line, BlockResult& result);

    /// Position after a change of TCP mode, converted by the caller (the interpreter knows no kinematics).
    void setPosition(const AxisVector& p, AxisMask known) {
        pos_ = p;
        known_ = known;
        assumed_ &= known;
    }
    ProgramMode mode() const { return mode_; }
    const AxisLayout& layout() const { return layout_; }
    const AxisVector& position() const { return pos_; }
    AxisMask known() const { return known_; }
    /// Rotary axes known only because they are taken at 0 until the program commands them.
    AxisMask assumed() const { return assumed_; }
    Motion motion() const { return motion_; }
    /// Value of a word in program units (Fanuc integer increments applied to dimension words).
    double wordValue(const Word& w) const { return wordValue(w, options_.dialect, inch_, layout_); }
    /// The same for a block read in `dialect` with G20 (`inch`) or G21 in effect (BlockResult::inch).
    static double wordValue(const Word& w, Dialect dialect, bool inch, const AxisLayout& layout) {
        // Called for every number read: here, so that it is inlined.
        if (dialect != Dialect::Fanuc || w.point) return w.value;
        const char c = w.letter;  // Fanuc: dimension words without a point count increments
        if (layout.axis(c) >= 0 || c == 'I' || c == 'J' || c == 'K' || c == 'R' || c == 'U' || c == 'V' || c == 'W')
            return w.value * (inch ? 1e-4 : 1e-3);
        return w.value;
    }

private:
    /// A result for a line passed through unread: no words, start and end at the current position.
    void unreadLine(BlockResult& r, const char* reason);
    void resetPositions();
    void warn(BlockResult& r, Warning w, int code);
    void passThrough(BlockResult& r, const char* reason, int code, bool report = true);
    void unknownAll(BlockResult& r);
    const AxisVector* offsetValues(int code) const;
    AxisMask offsetUnknown(int code) const;
    void fillConversions(BlockResult& r) const;
    /// Targets of the block's axis words (absolute or incremental) into r.end / r.endKnown; returns the
    /// first reason a target is unknown, or nullptr.
    const char* computeTargets(const LexedBlock& b, BlockResult& r, bool machineCoordinates) const;
    void commit(const BlockResult& r);
    bool arcGeometry(const LexedBlock& b, BlockResult& r, const char*& why);
    /// The result fields of a new block, before it is read (start = end = the current position).
    inline void beginBlock(BlockResult& r);  // once per block, in interpreter.cpp: inlined there

    // Convert: apply a read and checked block, in the RS274NGC order of execution (postproc/interp_convert.cpp).
    /// Passes the block through; its positions (and with why.forgetMotion its motion mode) become unknown.
    void refuse(BlockResult& r, const Refusal& why);
    /// Every modal code of the block, in order; a refusal stops the block (the codes before it have taken effect).
    Refusal convertModalCodes(const BlockWords& w, const GCodes& g, const LexedBlock& b, BlockResult& r,
                              ProgramMode modeBefore);
    void convertFeedPlaneUnits(const BlockWords& w, const GCodes& g, BlockResult& r);
    void convertToolLength(const BlockWords& w, const GCodes& g, const LexedBlock& b, BlockResult& r);
    Refusal convertWorkOffset(const BlockWords& w, const GCodes& g);
    void convertModes(const BlockWords& w, const GCodes& g, const LexedBlock& b, BlockResult& r, ProgramMode modeBefore);
    Refusal convertMotionMode(const BlockWords& w, const GCodes& g, BlockResult& r);
    /// The non-modal code that uses the axis words for something else (G4, G10, G28, G52, G92, G31 …); true when it
    /// ends the block.
    bool convertNonModal(const BlockWords& w, const GCodes& g, const LexedBlock& b, BlockResult& r);
    void convertOffsetData(const BlockWords& w, const LexedBlock& b, BlockResult& r);
    /// The block's tool vector in TCP vector mode (Fanuc G43.5 I J K, Sinumerik A3= B3= C3=).
    Refusal convertToolVector(const BlockWords& w, const LexedBlock& b, BlockResult& r);
    /// The block's axis motion: its targets, a move evaluated or the reason it is not.
    void convertMotion(const BlockWords& w, const LexedBlock& b, BlockResult& r, bool onlyModal, bool machineCoordinates);
    /// A move that is not corrected (machine coordinates, transformation, cycle, unknown position …): true when it was
    /// passed through.
    bool refuseMove(const BlockWords& w, BlockResult& r, bool machineCoordinates, const char* targetProblem);

    AxisLayout layout_;
    InterpreterOptions options_;
    // Modal state.
    Motion motion_ = Motion::Unknown;
    bool cycleActive_ = false;       ///< Fanuc canned cycle (separate modal group from G0/G1)
    int plane_ = 17;
    bool absolute_ = true, arcAbsolute_ = false, inch_ = false, unitsSet_ = false;
    bool diameter_ = false;
    FeedMode feedMode_ = FeedMode::PerMinute;
    double feed_ = 0.0;
    int offsetCode_ = 540;
    int tool_ = 0;
    int tloSign_ = 0;                ///< 0 none, +1 G43, -1 G44
    double tloLength_ = 0.0;         ///< mm
    bool tloKnown_ = true;
    bool tloAssumed_ = false;        ///< tloLength_ is the default length that nobody gave (G43 Hn with n not listed)
    ProgramMode mode_ = ProgramMode::Joints;  ///< TCP mode (TcpVector: Fanuc G43.5; Sinumerik vectors are per block)
    TcpSource tcpSource_ = TcpSource::None;
    bool transform_ = false, modalMacro_ = false, cutterComp_ = false;
    AxisVector local_;               ///< G52 local offset (machine units)
    AxisMask g92Unknown_ = 0;        ///< axes under a position-dependent G92 / G50 offset
    std::vector<std::pair<int, AxisVector>> offsets_;  ///< work offsets from the setup and G10 L2
    std::vector<std::pair<int, AxisMask>> offsetsUnknown_;  ///< set by G10 L20
    // Position.
    AxisVector pos_;
    AxisMask known_ = 0;
    AxisMask assumed_ = 0;           ///< axes taken at an assumed position (rotary 0, Setup::assumed) until commanded
    // Warnings already given.
    std::vector<std::pair<Warning, int>> warned_;
};

}  // namespace cnccomp::postproc
