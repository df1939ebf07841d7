#include "postproc/processor.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <cstring>
#include <exception>
#include <mutex>
#include <thread>
#include <istream>
#include <ostream>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/text_util.hpp"
#include "postproc/block_writer.hpp"
#include "postproc/klartext_correct.hpp"
#include "postproc/line_reader.hpp"
#include "cnccomp/io/number_format.hpp"

namespace cnccomp::pp {

void addNotice(CorrectSummary& summary, std::ostream* report, bool warning, uint64_t line, std::string message) {
    auto& list = warning ? summary.warnings : summary.passThrough;
    if (warning) ++summary.warningCount;
    if (report) {
        // Plain CSV without quoting (as every CSV of the project): commas in messages become semicolons.
        std::string m = message;
        std::replace(m.begin(), m.end(), ',', ';');
        *report << line << ',' << (warning ? "warning" : "pass-through") << ',' << m << '\n';
    }
    if (list.size() < CorrectSummary::kMaxNotices) list.push_back({line, std::move(message)});
}

double digitsTolerance(Corrector& corrector, const MoveSpace& space, const AxisVector& end, int linDecimals,
                       int rotDecimals, bool inch, int linearAxes, int rotaryAxes) {
    const double linStep = tenTo(-linDecimals) * (inch ? 25.4 : 1.0);
    double floor = 0.5 * linStep * std::sqrt(static_cast<double>(std::max(linearAxes, 1)));
    if (space.mode == ProgramMode::Joints && rotaryAxes > 0) {
        // Lever arm of the rotary axes at this pose: the tip's distance from the workpiece origin plus the tool.
        const double lever = corrector.nominalTip(end, space.toolLength).norm() + std::fabs(space.toolLength);
        floor += 0.5 * tenTo(-rotDecimals) * kDeg * lever * std::sqrt(static_cast<double>(rotaryAxes));
    }
    return floor;
}

double toleranceWithin(double tolMm, double floorMm, int linDecimals, CorrectSummary& summary, std::ostream* report,
                       uint64_t line, bool& warned) {
    if (tolMm >= floorMm) return tolMm;
    ++summary.clampedTolerance;
    summary.toleranceFloor = std::max(summary.toleranceFloor, floorMm);
    if (!warned) {
        warned = true;
        addNotice(summary, report, true, line,
                  fmt::format("--tol-um {:.3g} is below what the written digits can hold here ({:.3g} um with {} "
                              "decimals): moves are checked against {:.3g} um (--decimals writes more digits)",
                              tolMm / kUm, floorMm / kUm, linDecimals, floorMm / kUm));
    }
    return floorMm;
}

void refuseAssumedToolLength(Corrector& corrector, const AxisLayout& layout, const AxisVector& cNom,
                             const AxisVector& cEnd, double toolLength, double toleranceMm, const std::string& name,
                             uint64_t line) {
    bool rotaryOff = false;
    for (int a = 0; a < layout.count; ++a)
        if (layout.rotary[a] && std::fabs(cNom[a]) > 1e-9) rotaryOff = true;
    if (!rotaryOff) return;
    const double off = corrector.tipDeviation(cNom, cEnd, toolLength + kToolLengthProbeMm);
    if (!(off > toleranceMm)) return;
    throw InputError(name, static_cast<int>(std::min<uint64_t>(line, INT32_MAX)),
                     fmt::format("the correction of this rotary move depends on the tool length, which was not given: "
                                 "corrected for a tool point at {:g} mm, it leaves a point {:g} mm further along the tool "
                                 "{:.1f} um off its path; give the length the program was made for with --tool-length L "
                                 "(--tool-length 0 when 0 is meant; G43 Hn: --tool-length Hn=L or --tool-table)",
                                 toolLength, kToolLengthProbeMm, off / kUm));
}

std::optional<HeaderToolLength> toolLengthFromHeader(std::string_view head) {
    static constexpr std::string_view kHint = "cnccomp correct --tool-length ";
    uint64_t line = 0;
    while (!head.empty() && line < 200) {
        ++line;
        const size_t eol = head.find('\n');
        const std::string_view text = head.substr(0, eol);
        head = eol == std::string_view::npos ? std::string_view{} : head.substr(eol + 1);
        for (size_t i = 0; i + kHint.size() <= text.size(); ++i) {
            size_t k = 0;
            while (k < kHint.size() &&
                   std::tolower(static_cast<unsigned char>(text[i + k])) == static_cast<unsigned char>(kHint[k]))
                ++k;
            if (k < kHint.size()) continue;
            std::string_view rest = text.substr(i + k);
            size_t n = 0;
            while (n < rest.size() && (std::isdigit(static_cast<unsigned char>(rest[n])) || rest[n] == '.' ||
                                       rest[n] == '-' || rest[n] == '+' || rest[n] == 'e' || rest[n] == 'E'))
                ++n;
            const auto v = parseNumber(rest.substr(0, n));
            if (v && std::isfinite(*v) && std::fabs(*v) <= 1e5) return HeaderToolLength{*v, line};
        }
    }
    return std::nullopt;
}

void checkTextHead(std::string_view head, const std::string& name) {
    if (head.empty()) throw InputError(name, 0, "the program is empty (no bytes)");
    size_t control = 0;
    int line = 1;
    for (size_t i = 0; i < head.size(); ++i) {
        const unsigned char c = static_cast<unsigned char>(head[i]);
        if (c == '\n') ++line;
        if (c == 0)
            throw InputError(name, line,
                             fmt::format("binary data (a NUL byte at byte {}): not a G-code text file", i + 1));
        if (c < 0x20 && c != '\n' && c != '\r' && c != '\t' && c != '\f' && c != '\v' && c != 0x1a) ++control;
    }
    if (control * 20 > head.size())
        throw InputError(name, 0,
                         fmt::format("binary data ({} control bytes in the first {}): not a G-code text file", control,
                                     head.size()));
}

namespace {

struct LetterStyle {
    int maxDecimals = -1;
    bool trailingZero = false, bare = false, sawPoint = false, sawInteger = false;
};

const char* warningText(Warning w) {
    switch (w) {
        case Warning::OffsetNotGiven: return "work offset {} is used but not given (--work-offset); taken as zero";
        case Warning::ToolLengthNotGiven: return "tool length offset {} is not given (--tool-length Hn=…); the default length is used";
        case Warning::UnitsAssumed: return "the program sets neither G20 nor G21 before its first move; {} assumed";
        case Warning::RotaryAssumed: return "axis {} is not commanded before the first move; taken at its assumed position (rotary 0 deg, --assume)";
        case Warning::CutterCompensation: return "cutter radius compensation (G41/G42) is active: corrections are computed on the programmed path{}";
        case Warning::NoToolLengthAxis: return "G43 on a machine without a Z axis: no tool length offset applied{}";
    }
    return "{}";
}

double circular(double d) { return d - 360.0 * std::round(d / 360.0); }

/// How the words of one block are spaced and aligned, so that words added to it (or lines added after it) look like
/// its own: the white space between words, between a letter and its number, and whether positive numbers take the
/// place of a minus sign ("X  16.339  Y -25.409").
struct BlockStyle {
    std::array<char, 8> sep{};
    size_t sepLen = 0;
    int valueGap = 0;      ///< spaces between the letter and the number of the block's last axis word
    bool anchorNeg = false;
};

/// Where the nominal program or the output program is (unrounded), in the space it was read in; machine coordinates
/// and the tool vector there are computed when needed.
struct Where {
    bool known = false;
    MoveSpace space;
    ProgramPoint point;
    AxisVector joints;
    bool jointsValid = false;
    Vec3 vector = Vec3(0, 0, -1);
    bool vectorValid = false;
};

bool jointsOf(Corrector& corrector, Where& w, const AxisVector& guess) {
    if (!w.known) return false;
    if (!w.jointsValid) w.jointsValid = corrector.toJoints(w.space, w.point, guess, w.joints);
    return w.jointsValid;
}

bool vectorOf(Corrector& corrector, Where& w, const AxisVector& guess) {
    if (!w.known) return false;
    if (w.vectorValid) return true;
    if (w.space.mode == ProgramMode::TcpVector) {
        w.vector = w.point.v;
    } else {
        if (!jointsOf(corrector, w, guess)) return false;
        ProgramPoint p;
        corrector.toProgram(MoveSpace{ProgramMode::TcpVector, w.space.controlLength, w.space.toolLength}, w.joints, p);
        w.vector = p.v;
    }
    w.vectorValid = true;
    return true;
}

/// After a TCP mode switch: the same machine position read in the new mode (false when it is not known).
bool convertWhere(Corrector& corrector, Where& w, const MoveSpace& space, const AxisVector& guess) {
    if (!jointsOf(corrector, w, guess)) {
        w.known = false;
        return false;
    }
    const AxisVector joints = w.joints;
    w.space = space;
    corrector.toProgram(space, joints, w.point);
    w.joints = joints;
    w.jointsValid = true;
    w.vectorValid = false;
    return true;
}

/// One line as the front end read it — lexed, interpreted and, for a move, its end point corrected — handed in program
/// order to the back end, which checks and splits the path and writes the text. Every value the back end needs from
/// the front end's running state is in here, so the two can run on two threads with the same results as on one.
struct Record {
    std::string text;
    std::array<char, 2> eol{};
    uint8_t eolLen = 0;
    uint64_t number = 0, bytesConsumed = 0;
    bool partial = false, firstPiece = true, lastPiece = true;
    LexedBlock b;
    BlockResult r;
    AxisMask assumed = 0;           ///< axes taken at an assumed position (Interpreter::assumed) after this block
    bool overlongCode = false;      ///< last piece of an overlong line that holds code
    bool overlongModal = false;     ///< … whose codes may change any mode (Interpreter::forgetOverlong)
    // A move (r.kind Move), or one the front end refused (r.kind PassThrough, frontRefused):
    bool frontRefused = false;      ///< counted as a move, then passed through (r.reason says why)
    bool forgetOutput = false;      ///< the output position is unknown after it (TCP on a machine without X Y Z)
    MoveSpace space;
    bool nomStartKnown = false, corrected = false, unconverged = false, outsideTravel = false, jointsComputed = false;
    ProgramPoint nomStart, nomEnd;
    AxisVector cNom, cEnd;
    double tipResidual = 0, axisResidual = 0;  ///< of the end point's solution
    std::vector<std::pair<bool, std::string>> notices;  ///< (warning, text) raised by the front end, in order
    std::string_view eolView() const { return {eol.data(), eolLen}; }
    void note(bool warning, std::string message) { notices.emplace_back(warning, std::move(message)); }
};

/// The front end: reads lines, lexes and interprets them, follows the nominal program and corrects move end points
/// (each from the previous one's correction: warm start and continuity).
class FrontEnd {
public:
    FrontEnd(const MachineModel& m, const DeviationSet& d, const CorrectOptions& o, Dialect dialect, LineReader& reader)
        : machine_(m),
          options_(o),
          dialect_(dialect),
          layout_(AxisLayout::fromMachine(m)),
          interp_(layout_, InterpreterOptions{dialect, o.setup, o.rotaryShortest, o.tcpOnM, o.tcpOffM}),
          corrector_(m, d, o.corrector),
          reader_(reader) {
        lastDelta_ = AxisVector::Zero(layout_.count);
        all_ = layout_.all();
        for (int a = 0; a < layout_.count; ++a) {  // travel in the controller's machine coordinates
            const Link& link = m.axisLink(a);
            travelMin_[a] = link.min - link.machineZero;
            travelMax_[a] = link.max - link.machineZero;
        }
    }

    /// The next line into `rec`; false at the end of the input.
    bool next(Record& rec);

private:
    void afterPassThrough(const BlockResult& r);
    void switchMode(const BlockResult& r);
    void move(Record& rec);
    void refuse(Record& rec, const char* reason);
    void checkTravel(Record& rec);

    const MachineModel& machine_;
    const CorrectOptions& options_;
    Dialect dialect_;
    AxisLayout layout_;
    Interpreter interp_;
    Corrector corrector_;
    LineReader& reader_;
    Line line_;
    OverlongLine long_;
    Where nomAt_;
    AxisVector lastDelta_, lastCNom_;
    double travelMin_[kMaxAxes] = {}, travelMax_[kMaxAxes] = {};
    bool haveDelta_ = false;  ///< lastDelta_ is the correction at the previous end point (continuity)
    AxisMask all_ = 0;
};

bool FrontEnd::next(Record& rec) {
    if (!reader_.next(line_)) return false;
    const Line& ln = line_;
    rec.text.assign(ln.text);
    rec.eolLen = static_cast<uint8_t>(std::min<size_t>(ln.eol.size(), 2));
    std::copy_n(ln.eol.begin(), rec.eolLen, rec.eol.begin());
    rec.number = ln.number;
    rec.bytesConsumed = reader_.bytesConsumed();
    rec.partial = ln.partial;
    rec.firstPiece = ln.firstPiece;
    rec.lastPiece = ln.lastPiece;
    rec.notices.clear();
    rec.frontRefused = rec.forgetOutput = rec.corrected = rec.unconverged = rec.outsideTravel = false;
    rec.overlongCode = rec.overlongModal = false;
    if (ln.partial) {
        if (ln.firstPiece) long_.reset();
        long_.feed(ln.text);
        if (ln.lastPiece && long_.code) {
            rec.overlongCode = true;
            rec.overlongModal = interp_.forgetOverlong(long_, rec.r);
            if (rec.overlongModal || rec.r.words) nomAt_.known = false;
        }
        return true;
    }
    lexBlock(rec.text, dialect_, rec.b, ln.number == 1);
    interp_.interpret(rec.text, rec.b, rec.r);
    rec.assumed = interp_.assumed();
    switch (rec.r.kind) {
        case BlockKind::Empty: break;
        case BlockKind::NoMotion:
            if (rec.r.modeSwitch) switchMode(rec.r);
            break;
        case BlockKind::PassThrough: afterPassThrough(rec.r); break;
        case BlockKind::Move: move(rec); break;
    }
    return true;
}

void FrontEnd::afterPassThrough(const BlockResult& r) {
    // The machine is where the nominal program puts it (joint mode); in TCP mode its joints are not followed.
    if (r.words || r.vectorGiven) {
        if (r.mode != ProgramMode::Joints) {
            nomAt_.known = false;
        } else {
            const MoveSpace joints{ProgramMode::Joints, 0.0, r.tipLength};
            nomAt_ = Where{(r.endKnown & all_) == all_, joints, ProgramPoint{r.end, Vec3(0, 0, -1)}, r.end, true};
        }
    }
    if (r.modeSwitch) nomAt_.known = false;  // a move in the block that switches TCP mode: unknown in the new mode
}

void FrontEnd::switchMode(const BlockResult& r) {
    // The controller's position is the same machine; what the program's numbers mean changes (LinuxCNC re-reads the
    // world position of the new kinematics at the switch: M66 E0 L0 in the M428/M429 remaps).
    AxisMask rotary = 0;
    for (int a = 0; a < layout_.count; ++a)
        if (layout_.rotary[a]) rotary |= 1u << a;
    if (convertWhere(corrector_, nomAt_, MoveSpace{r.mode, r.controlLength, r.tipLength}, r.end)) {
        interp_.setPosition(nomAt_.point.p, all_);
    } else {
        // Rotary angles are the same numbers in both modes; the linear positions are not known in the new one.
        interp_.setPosition(interp_.position(), interp_.known() & rotary);
    }
}

void FrontEnd::refuse(Record& rec, const char* reason) {
    rec.r.kind = BlockKind::PassThrough;
    rec.r.reason = reason;
    rec.r.report = true;
    afterPassThrough(rec.r);
}

void FrontEnd::checkTravel(Record& rec) {
    const AxisVector &cNom = rec.cNom, &c = rec.cEnd;
    for (int a = 0; a < layout_.count; ++a) {
        const double lo = travelMin_[a], hi = travelMax_[a];
        const bool nomOut = cNom[a] < lo - 1e-9 || cNom[a] > hi + 1e-9;
        const bool corOut = c[a] < lo - 1e-9 || c[a] > hi + 1e-9;
        if (!nomOut && !corOut) continue;
        rec.outsideTravel = true;
        const double k = layout_.rotary[a] ? 1.0 / kDeg : 1.0;
        const char* unit = layout_.rotary[a] ? "deg" : "mm";
        rec.note(true, fmt::format("axis {} at {:.4f} {} ({}) is outside its travel [{:g}, {:g}] {}: corrected all the same",
                                   layout_.letter[a], (nomOut ? cNom[a] : c[a]) * k, unit,
                                   nomOut ? "as programmed" : "after correction", lo * k, hi * k, unit));
    }
}

void FrontEnd::move(Record& rec) {
    BlockResult& r = rec.r;
    const MoveSpace space{r.mode, r.controlLength, r.tipLength};
    rec.space = space;
    const bool tcp = space.mode != ProgramMode::Joints;
    if (tcp && !corrector_.tcp().supported()) {
        refuse(rec, corrector_.tcp().why());
        rec.forgetOutput = true;
        return;
    }
    const bool identity = corrector_.identity();
    const bool vector = space.mode == ProgramMode::TcpVector;
    bool nomStartKnown = (r.startKnown & all_) == all_;
    const AxisVector guess = nomAt_.known && nomAt_.jointsValid ? nomAt_.joints : r.end;

    // Nominal end point in program space (vector mode: the programmed vector, tip → spindle, or the kept one).
    ProgramPoint& nomEnd = rec.nomEnd;
    ProgramPoint& nomStart = rec.nomStart;
    nomEnd.p = r.end;
    nomStart.p = r.start;
    nomEnd.v = nomStart.v = Vec3(0, 0, -1);
    if (vector) {
        const bool nomVector = nomStartKnown && vectorOf(corrector_, nomAt_, guess);
        nomStartKnown = nomStartKnown && nomVector;
        nomStart.v = nomAt_.vector;
        nomEnd.v = r.vectorGiven ? Vec3(-r.vector[0], -r.vector[1], -r.vector[2]).normalized() : nomAt_.vector;
        if (!r.vectorGiven && !nomVector) {
            refuse(rec, "tool vector not known yet (no I J K / A3 B3 C3 given since TCP was switched on)");
            return;
        }
    }
    rec.nomStartKnown = nomStartKnown;

    // Corrected end point: nominal machine coordinates, the erroneous machine's solution, its program position.
    AxisVector& cNom = rec.cNom;
    AxisVector& cEnd = rec.cEnd;
    NominalPose nomPose;
    if (identity && !vector) {
        cNom = r.end;  // not the machine coordinates in TCP mode: not used for anything but guesses
    } else if (!corrector_.toJoints(space, nomEnd, guess, cNom, &nomPose)) {
        refuse(rec, "the controller's TCP kinematics cannot reach this tool vector (no rotary solution)");
        rec.frontRefused = true;
        return;
    }
    rec.tipResidual = rec.axisResidual = 0;
    if (identity) {
        cEnd = cNom;
    } else {
        // Near the previous end point's correction (warm start and continuity) and the programmed value.
        AxisVector start;
        if (haveDelta_) corrector_.predictStart(cNom, lastCNom_, lastDelta_, space.toolLength, start);
        else start = cNom + lastDelta_;
        const SolveResult s = corrector_.solve(cNom, space.toolLength, start, cEnd, haveDelta_ ? &lastDelta_ : nullptr,
                                               Vec3::Zero(), &nomPose);
        rec.tipResidual = s.tipError;
        rec.axisResidual = s.axisError;
        if (!s.converged || !(s.tipError < 1e-5)) {
            rec.unconverged = true;
            rec.note(true, fmt::format("the correction did not converge (tip residual {:.3g} um); end point left uncorrected",
                                       s.tipError / kUm));
            cEnd = cNom;
        } else {
            if (r.tipLengthAssumed && options_.requireToolLength)
                refuseAssumedToolLength(corrector_, layout_, cNom, cEnd, space.toolLength, options_.corrector.toleranceMm,
                                        options_.inputName, rec.number);
            lastDelta_ = cEnd - cNom;
            lastCNom_ = cNom;
            haveDelta_ = true;
            rec.corrected = true;  // the back end writes cEnd's program position (toProgram)
        }
    }
    if (!(identity && tcp && !vector)) checkTravel(rec);
    rec.jointsComputed = !identity || vector || !tcp;
    nomAt_ = Where{true, space, nomEnd, cNom, rec.jointsComputed, nomEnd.v, vector};
}

class ProgramCorrector {
public:
    ProgramCorrector(const MachineModel& m, const DeviationSet& d, const CorrectOptions& o, Dialect dialect,
                     CorrectSummary& s, OutputBuffer& out)
        : machine_(m),
          options_(o),
          dialect_(dialect),
          layout_(AxisLayout::fromMachine(m)),
          corrector_(m, d, o.corrector),
          summary_(s),
          out_(out) {
        const int n = layout_.count;
        outPos_ = AxisVector::Zero(n);
        pieces_.reserve(static_cast<size_t>(o.corrector.maxPieces) + 4);
        all_ = layout_.all();
        for (int a = 0; a < n; ++a) {
            if (layout_.rotary[a]) ++rotaryCount_;
            else ++linearCount_;
        }
    }

    void line(Record& rec);

private:
    void notice(bool warning, uint64_t line, std::string message);
    void overlong(const Record& rec);
    void updateStyles(const LexedBlock& b, std::string_view text);
    void blockStyle(std::string_view text);
    void warnings(uint64_t no);
    void passThrough(const Line& ln, uint64_t no);
    void move(Record& rec);
    void switchMode();
    void updateOutputAfterPassThrough();
    double toleranceFor(const MoveSpace& space, uint64_t no);
    // Text helpers.
    int decimalsFor(char letter, bool rotary) const;
    NumberStyle styleFor(char letter, bool rotary, const Word* original, bool& increments) const;
    size_t number(char letter, bool rotary, double programValue, const Word* original, char* out, double& readBack,
                  double& resolution) const;
    size_t motionText(Motion m, char* out) const;
    char letterCase(char c) const { return b_->lowerCase ? static_cast<char>(c | 0x20) : c; }
    /// A new word "X  -1.25" in the block's style (separator first when `separated`).
    size_t composeWord(char letter, const char* num, size_t n, int ext, bool separated, char* out) const;
    /// Replaces a word's number, keeping a sign-aligned column aligned.
    void replaceNumber(const Word& w, const char* num, size_t n);
    /// Word needed for axis a to reach q (program space)? Writes the number (replace) or a new word into text (len)
    /// and updates the output position. `existing` is the word index in the block (piece 1) or -1.
    bool axisWord(int a, double q, int existing, char* text, size_t& len, bool& replace);
    /// Vector words (I J K / A3= B3= C3=) for the tool vector v (world, spindle → tip): replaced in place on the
    /// block (onBlock) or appended to `buf`.
    void vectorWords(const Vec3& v, bool onBlock, char* buf, size_t& used);
    bool insertMotionWord(Motion m);
    size_t arcWords(const ArcFit& fit, const AxisVector& outStart, uint32_t insertPos);

    const MachineModel& machine_;
    const CorrectOptions& options_;
    Dialect dialect_;
    AxisLayout layout_;
    Corrector corrector_;
    CorrectSummary& summary_;
    OutputBuffer& out_;
    const LexedBlock* b_ = nullptr;  ///< the current record's block
    BlockResult* r_ = nullptr;
    BlockEdits edits_;
    BlockStyle style_;
    std::array<LetterStyle, 26> styles_{};
    LetterStyle vectorStyle_;
    bool gPadded_ = false;
    bool fixedProgram_ = false;  ///< some dimension word keeps trailing zeros: write fixed decimals everywhere
    bool alignSign_ = false;     ///< positive numbers take one more space than negative ones ("X  1.0  Y -2.0")
    std::array<char, 8> programSep_{{' '}};  ///< separator of the last block with two words or more
    size_t programSepLen_ = 1;
    std::string_view lineText_;  ///< the current block's text
    bool sawNegative_ = false;
    // Output program: position in program space as written (read back from the written digits), tool vector, joints.
    AxisVector outPos_;
    AxisMask outKnown_ = 0, all_ = 0;
    Vec3 outVector_ = Vec3(0, 0, -1);  ///< tool vector as written (vector mode), world, spindle → tip
    bool outVectorKnown_ = false;
    Where outAt_;
    bool offCourse_ = true;      ///< the output's position is not the corrected nominal one (start, after pass-through)
    Motion outMotion_ = Motion::Unknown;
    std::vector<Piece> pieces_;
    int linearCount_ = 0, rotaryCount_ = 0;
    bool warnedCr_ = false, warnedTolerance_ = false;
    std::string lastEol_ = "\n";
};

void ProgramCorrector::notice(bool warning, uint64_t line, std::string message) {
    addNotice(summary_, options_.report, warning, line, std::move(message));
}

void ProgramCorrector::updateStyles(const LexedBlock& b, std::string_view text) {
    for (int i = 0; i < b.count; ++i) {
        const Word& w = b.words[i];
        if (w.kind != ValueKind::Number) continue;
        LetterStyle& s = w.ext ? vectorStyle_ : styles_[w.letter - 'A'];
        if (w.point) {
            s.sawPoint = true;
            if (w.decimals > s.maxDecimals) s.maxDecimals = w.decimals;
            if (w.trailingZero) {
                s.trailingZero = true;
                if (w.letter != 'F' && w.letter != 'S' && w.letter != 'G' && w.letter != 'M') fixedProgram_ = true;
            }
            if (w.bareFraction) s.bare = true;
        } else {
            s.sawInteger = true;
            if (s.maxDecimals < 0) s.maxDecimals = 0;
        }
        if (w.letter == 'G' && w.digitsBefore == 2 && w.value < 10) gPadded_ = true;
    }
    // A sign column ("X  1.0  Y -2.0"): in a block, a positive number has one space more than a negative one; before
    // any negative number is seen, two spaces or more before a positive one. Words without spaces say nothing.
    int pos = -1, neg = -1;
    for (int i = 0; i < b.count; ++i) {
        const Word& w = b.words[i];
        if (w.kind != ValueKind::Number || w.ext || layout_.axis(w.letter) < 0) continue;
        const int gap = static_cast<int>(w.valueBegin - w.begin) - 1;
        if (gap <= 0 && text[w.valueBegin] != '-') continue;
        (text[w.valueBegin] == '-' ? neg : pos) = gap;
    }
    if (pos >= 0 && neg >= 0) {
        alignSign_ = pos == neg + 1;
        sawNegative_ = true;
    } else if (neg >= 0) {
        sawNegative_ = true;
    } else if (pos >= 0 && !sawNegative_) {
        alignSign_ = pos >= 2;
    }
}

void ProgramCorrector::blockStyle(std::string_view text) {
    // Anchor: the last axis word of the block, else its last word.
    int anchor = -1;
    for (int i = 0; i < b_->count; ++i)
        if (layout_.axis(b_->words[i].letter) >= 0 && !b_->words[i].ext) anchor = i;
    if (anchor < 0) anchor = b_->count - 1;
    style_ = BlockStyle{};
    auto setSep = [&](std::string_view ws) {
        style_.sepLen = std::min(ws.size(), style_.sep.size());
        std::copy_n(ws.begin(), style_.sepLen, style_.sep.begin());
    };
    setSep(std::string_view(programSep_.data(), programSepLen_));
    if (anchor < 0) return;
    const Word& w = b_->words[anchor];
    style_.valueGap = static_cast<int>(w.valueBegin - w.begin) - 1;
    style_.anchorNeg = w.valueBegin < text.size() && text[w.valueBegin] == '-';
    if (anchor == 0) return;  // no word before it: the program's usual separator
    // The white space between the anchor and the token before it is this block's separator (and the program's).
    size_t a = w.begin;
    while (a > 0 && (text[a - 1] == ' ' || text[a - 1] == '\t')) --a;
    setSep(text.substr(a, w.begin - a));
    programSepLen_ = style_.sepLen;
    programSep_ = style_.sep;
}

size_t ProgramCorrector::composeWord(char letter, const char* num, size_t n, int ext, bool separated, char* out) const {
    size_t len = 0;
    if (separated)
        for (size_t k = 0; k < style_.sepLen; ++k) out[len++] = style_.sep[k];
    out[len++] = letterCase(letter);
    if (ext) {
        out[len++] = static_cast<char>('0' + ext);
        out[len++] = '=';
    } else {
        int gap = style_.valueGap;
        if (alignSign_) {
            // The sign takes a space of the column; a block that separates letter and number keeps one at least.
            const int width = gap + (style_.anchorNeg ? 1 : 0);
            gap = std::max(style_.valueGap > 0 || style_.anchorNeg ? 1 : 0, width - ((n > 0 && num[0] == '-') ? 1 : 0));
        }
        for (int k = 0; k < gap && k < 8; ++k) out[len++] = ' ';
    }
    std::memcpy(out + len, num, n);
    return len + n;
}

void ProgramCorrector::replaceNumber(const Word& w, const char* num, size_t n) {
    const std::string_view text = lineText_;
    const bool wasNeg = w.valueBegin < text.size() && text[w.valueBegin] == '-';
    const bool isNeg = n > 0 && num[0] == '-';
    if (alignSign_ && !w.ext && wasNeg != isNeg) {
        if (isNeg && w.valueBegin > w.begin + 1 && text[w.valueBegin - 1] == ' ') {
            edits_.add(w.valueBegin - 1, w.end, std::string_view(num, n));  // "X  1.0" → "X -1.0"
            return;
        }
        if (!isNeg) {
            char t[kMaxNumberChars + 2];
            t[0] = ' ';
            std::memcpy(t + 1, num, n);
            edits_.add(w.valueBegin, w.end, std::string_view(t, n + 1));  // "X -1.0" → "X  1.0"
            return;
        }
    }
    edits_.add(w.valueBegin, w.end, std::string_view(num, n));
}

void ProgramCorrector::warnings(uint64_t no) {
    for (int k = 0; k < r_->warningCount; ++k) {
        const auto [w, code] = r_->warnings[k];
        std::string detail;
        switch (w) {
            case Warning::OffsetNotGiven: detail = offsetCodeName(code); break;
            case Warning::ToolLengthNotGiven: detail = fmt::format("H{}", code); break;
            case Warning::UnitsAssumed: detail = code ? "inch" : "mm"; break;
            case Warning::RotaryAssumed: detail = std::string(1, static_cast<char>(code)); break;
            default: break;
        }
        notice(true, no, fmt::format(fmt::runtime(warningText(w)), detail));
    }
}

int ProgramCorrector::decimalsFor(char letter, bool rotary) const {
    if (options_.decimals >= 0) return options_.decimals;
    const int floor = rotary ? 4 : (r_->inch ? 5 : 4);
    return std::max(styles_[letter - 'A'].maxDecimals, floor);
}

NumberStyle ProgramCorrector::styleFor(char letter, bool rotary, const Word* original, bool& increments) const {
    const LetterStyle& ls = styles_[letter - 'A'];
    NumberStyle st;
    increments = r_->integerIncrements && letter != 'F' &&
                 ((original && !original->point) || (!original && ls.sawInteger && !ls.sawPoint));
    st.point = !increments;
    st.decimals = decimalsFor(letter, rotary);
    st.fixed = ls.trailingZero || fixedProgram_;
    st.bareFraction = ls.bare;
    st.plus = original && original->plus;
    return st;
}

size_t ProgramCorrector::number(char letter, bool rotary, double pv, const Word* original, char* out, double& readBack,
                                double& resolution) const {
    bool increments = false;
    const NumberStyle st = styleFor(letter, rotary, original, increments);
    if (increments) {
        const double counts = std::round(pv / r_->increment);
        readBack = counts * r_->increment;
        resolution = r_->increment;
        return formatNumber(counts, st, out);
    }
    static constexpr double kStep[] = {1, 1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12, 1e-13, 1e-14, 1e-15};
    readBack = roundToStyle(pv, st);
    resolution = kStep[std::clamp(st.decimals, 0, 15)];
    return formatNumber(pv, st, out);
}

size_t ProgramCorrector::motionText(Motion m, char* out) const {
    const int code = m == Motion::Rapid ? 0 : m == Motion::Linear ? 1 : m == Motion::ArcCw ? 2 : 3;
    size_t n = 0;
    out[n++] = letterCase('G');
    if (gPadded_) out[n++] = '0';
    out[n++] = static_cast<char>('0' + code);
    return n;
}

bool ProgramCorrector::axisWord(int a, double q, int existing, char* text, size_t& len, bool& replace) {
    const AxisMask bit = 1u << a;
    const bool rotary = layout_.rotary[a];
    const bool wrap = (r_->wrap & bit) != 0;
    const bool absolute = r_->absolute || r_->machineCoordinates;
    const double scale = r_->scale[a], off = r_->offset[a];
    const Word* orig = existing >= 0 ? &b_->words[existing] : nullptr;
    const double origPv = orig ? Interpreter::wordValue(*orig, dialect_, r_->inch, layout_) : 0.0;
    replace = false;
    len = 0;
    if (!absolute && !(outKnown_ & bit)) {
        // Incremental from an unknown output position: nothing sensible to write; keep the program's word.
        return false;
    }
    double pv = absolute ? (q - off) / scale : (q - outPos_[a]) / scale;
    if (wrap && absolute) pv = pv - 360.0 * std::floor(pv / 360.0);
    char num[kMaxNumberChars];
    double readBack = 0, res = 0;
    const size_t n = number(layout_.letter[a], rotary, pv, orig, num, readBack, res);
    auto diff = [&](double x, double y) { return wrap && absolute ? circular(x - y) : x - y; };
    if (orig) {
        if (std::fabs(diff(pv, origPv)) < 0.5 * res) {
            // The correction does not show at this resolution: keep the program's bytes.
            if (absolute) outPos_[a] = wrap ? q + diff(origPv, pv) * scale : origPv * scale + off;
            else outPos_[a] += origPv * scale;
            outKnown_ |= bit;
            return false;
        }
    } else if (absolute && (outKnown_ & bit)) {
        // A word the block does not have is added only for a change of at least one output digit: a dead band
        // that keeps corrections at the rounding level from flickering in and out of every block.
        const double held = (outPos_[a] - off) / scale;
        if (std::fabs(diff(pv, held)) < res * (1.0 - 1e-9)) return false;
    } else if (!absolute) {
        if (std::fabs(pv) < res * (1.0 - 1e-9)) return false;
    }
    if (absolute) outPos_[a] = wrap ? q + diff(readBack, pv) * scale : readBack * scale + off;
    else outPos_[a] += readBack * scale;
    outKnown_ |= bit;
    if (orig) {
        replace = true;
        std::memcpy(text, num, n);
        len = n;
    } else {
        len = composeWord(layout_.letter[a], num, n, 0, true, text);
    }
    return true;
}

void ProgramCorrector::vectorWords(const Vec3& v, bool onBlock, char* buf, size_t& used) {
    // Written vector: tip → spindle (Fanuc I J K, Sinumerik A3 B3 C3), all three components (omitted ones read as 0).
    const Vec3 w = -v.normalized();
    const bool sinumerik = r_->tcpSource == TcpSource::Sinumerik;
    const char letters[3] = {sinumerik ? 'A' : 'I', sinumerik ? 'B' : 'J', sinumerik ? 'C' : 'K'};
    const int ext = sinumerik ? 3 : 0;
    NumberStyle st;
    st.decimals = options_.decimals >= 0 ? options_.decimals : std::max(vectorStyle_.maxDecimals, 7);
    st.fixed = vectorStyle_.trailingZero;
    st.bareFraction = vectorStyle_.bare;
    const double res = tenTo(-st.decimals);
    // Unchanged at the written resolution: keep the program's words (or its kept vector).
    Vec3 given = outVector_;
    bool anyWord = false;
    if (onBlock && r_->vectorGiven) {
        Vec3 g(r_->vector[0], r_->vector[1], r_->vector[2]);
        given = -g.normalized();
        anyWord = true;
    }
    if (outVectorKnown_ || anyWord) {
        const Vec3 old = -given;
        if ((w - old).cwiseAbs().maxCoeff() < 0.5 * res) {
            outVector_ = given;
            outVectorKnown_ = true;
            return;
        }
    }
    Vec3 back;
    for (int k = 0; k < 3; ++k) {
        char num[kMaxNumberChars];
        const size_t n = formatNumber(w[k], st, num);
        back[k] = roundToStyle(w[k], st);
        const int wi = onBlock ? r_->vectorWord[k] : -1;
        if (wi >= 0) {
            replaceNumber(b_->words[wi], num, n);
        } else {
            used += composeWord(letters[k], num, n, ext, true, buf + used);
        }
    }
    outVector_ = -back.normalized();
    outVectorKnown_ = true;
}

bool ProgramCorrector::insertMotionWord(Motion m) {
    char t[16];
    size_t n = 0;
    const bool lead = b_->count > 0 && b_->words[0].letter == 'N';
    uint32_t pos = lead ? b_->words[0].end : (b_->count > 0 ? b_->words[0].begin : b_->codeEnd);
    const bool spaced = style_.sepLen > 0;
    if (lead && spaced)
        for (size_t k = 0; k < style_.sepLen; ++k) t[n++] = style_.sep[k];
    n += motionText(m, t + n);
    if (!lead && spaced)
        for (size_t k = 0; k < style_.sepLen; ++k) t[n++] = style_.sep[k];
    return edits_.add(pos, pos, std::string_view(t, n));
}

void ProgramCorrector::updateOutputAfterPassThrough() {
    const bool tcp = r_->mode != ProgramMode::Joints;
    for (int a = 0; a < layout_.count; ++a) {
        const AxisMask bit = 1u << a;
        if (!(r_->endKnown & bit)) {
            outKnown_ &= ~bit;
            continue;
        }
        if (!(r_->words & bit)) continue;
        if (r_->absolute || r_->machineCoordinates) {
            outPos_[a] = r_->end[a];
            outKnown_ |= bit;
        } else if ((outKnown_ & bit) && (r_->startKnown & bit)) {
            outPos_[a] += r_->end[a] - r_->start[a];
        } else {
            outKnown_ &= ~bit;
        }
    }
    // The machine is where the nominal program puts it (joint mode); in TCP mode its joints are not followed.
    if (r_->words || r_->vectorGiven) {
        offCourse_ = true;
        outVectorKnown_ = false;
        if (tcp) {
            outAt_.known = false;
        } else {
            const MoveSpace joints{ProgramMode::Joints, 0.0, r_->tipLength};
            outAt_ = Where{(outKnown_ & all_) == all_, joints, ProgramPoint{outPos_, Vec3(0, 0, -1)}, outPos_, true};
        }
    }
}

void ProgramCorrector::passThrough(const Line& ln, uint64_t no) {
    ++summary_.passedThrough;
    if (!r_->report) ++summary_.notCorrected;
    edits_.clear();
    // After an arc was turned into lines, the output's modal motion differs: restore it where this block relies on it.
    const bool relies = r_->words != 0 && !r_->motionCode;
    const bool motionKnown = r_->motion == Motion::Rapid || r_->motion == Motion::Linear || r_->motion == Motion::ArcCw ||
                             r_->motion == Motion::ArcCcw;
    bool restored = false;
    if (relies && motionKnown && outMotion_ != r_->motion && !edits_.overflow()) restored = insertMotionWord(r_->motion);
    if (r_->report) {
        std::string detail;
        if (r_->reasonLetter) detail = fmt::format(" (axis {})", r_->reasonLetter);
        else if (r_->reasonCode)
            detail = r_->reasonCode % 10 ? fmt::format(" (G{}.{})", r_->reasonCode / 10, r_->reasonCode % 10)
                                        : fmt::format(" (G{})", r_->reasonCode / 10);
        notice(false, no, fmt::format("{}{}{}", r_->reason ? r_->reason : "not evaluated", detail,
                                      restored ? "; motion word inserted to keep the modal motion" : ""));
    }
    if (restored) {
        edits_.apply(ln.text, out_);
        ++summary_.corrected;
    } else {
        out_.write(ln.text);
    }
    out_.write(ln.eol);
    if (r_->motionCode) outMotion_ = r_->motion;
    if (restored) outMotion_ = r_->motion;
    updateOutputAfterPassThrough();
    if (r_->modeSwitch) {
        // A move in the block that switches TCP mode: positions unknown in the new mode.
        outKnown_ = 0;
        outAt_.known = outVectorKnown_ = false;
    }
}

size_t ProgramCorrector::arcWords(const ArcFit& fit, const AxisVector& outStart, uint32_t insertPos) {
    // Centre words of the plane: (I,J) G17, (K,I) G18, (J,K) G19, or R.
    const int a0 = r_->arc.axis0, a1 = r_->arc.axis1;
    const char l0 = layout_.letter[a0] == 'X' ? 'I' : layout_.letter[a0] == 'Y' ? 'J' : 'K';
    const char l1 = layout_.letter[a1] == 'X' ? 'I' : layout_.letter[a1] == 'Y' ? 'J' : 'K';
    size_t changes = 0;
    char num[kMaxNumberChars];
    double readBack, res;
    if (r_->arc.radiusForm) {
        const Word* R = b_->find('R');
        const double radius = std::hypot(outStart[a0] - fit.c0, outStart[a1] - fit.c1) / r_->scale[a0];
        const double origPv = Interpreter::wordValue(*R, dialect_, r_->inch, layout_);
        const double pv = origPv < 0 ? -radius : radius;
        const size_t n = number('R', false, pv, R, num, readBack, res);
        if (std::fabs(pv - origPv) >= 0.5 * res) {
            edits_.add(R->valueBegin, R->end, std::string_view(num, n));
            ++changes;
        }
        return changes;
    }
    const double c[2] = {fit.c0, fit.c1};
    const int ax[2] = {a0, a1};
    const char let[2] = {l0, l1};
    for (int k = 0; k < 2; ++k) {
        const int a = ax[k];
        const double pv = r_->arcAbsolute ? (c[k] - r_->offset[a]) / r_->scale[a] : (c[k] - outStart[a]) / r_->scale[a];
        const Word* w = b_->find(let[k]);
        const double origPv = w ? Interpreter::wordValue(*w, dialect_, r_->inch, layout_) : 0.0;
        const size_t n = number(let[k], false, pv, w, num, readBack, res);
        if (std::fabs(pv - origPv) < 0.5 * res) continue;
        ++changes;
        if (w) {
            replaceNumber(*w, num, n);
        } else {
            char t[kMaxNumberChars + 16];
            const size_t len = composeWord(let[k], num, n, 0, true, t);
            edits_.add(insertPos, insertPos, std::string_view(t, len));
        }
    }
    return changes;
}

double ProgramCorrector::toleranceFor(const MoveSpace& space, uint64_t no) {
    // The written digits bound what any subdivision can achieve: each end point is off by up to half a digit per
    // axis (in joint mode a rotary digit moves the tip by its lever arm). A tolerance below that only multiplies
    // the program; it is raised to the bound, and the summary says so.
    const double tol = options_.corrector.toleranceMm;
    int linDecimals = 15, rotDecimals = 15;
    for (int a = 0; a < layout_.count; ++a) {
        const int d = decimalsFor(layout_.letter[a], layout_.rotary[a]);
        const bool fanucInt = r_->integerIncrements && !styles_[layout_.letter[a] - 'A'].sawPoint &&
                              styles_[layout_.letter[a] - 'A'].sawInteger;
        const int dd = fanucInt ? static_cast<int>(std::lround(-std::log10(r_->increment))) : d;
        if (layout_.rotary[a]) rotDecimals = std::min(rotDecimals, dd);
        else linDecimals = std::min(linDecimals, dd);
    }
    const double floor = digitsTolerance(corrector_, space, r_->end, linDecimals, rotDecimals, r_->inch, linearCount_,
                                         rotaryCount_);
    return toleranceWithin(tol, floor, linDecimals, summary_, options_.report, no, warnedTolerance_);
}

void ProgramCorrector::switchMode() {
    // The same machine position read in the new mode (the front end did the same for the nominal program).
    AxisMask rotary = 0;
    for (int a = 0; a < layout_.count; ++a)
        if (layout_.rotary[a]) rotary |= 1u << a;
    if (convertWhere(corrector_, outAt_, MoveSpace{r_->mode, r_->controlLength, r_->tipLength}, r_->end)) {
        outPos_ = outAt_.point.p;
        outKnown_ = all_;
    } else {
        outKnown_ &= rotary;
    }
    outVectorKnown_ = false;
    offCourse_ = true;
}

void ProgramCorrector::move(Record& rec) {
    const int n = layout_.count;
    const Line ln{rec.text, rec.eolView(), rec.number, false, true, true};
    const uint64_t no = rec.number;
    const MoveSpace space = rec.space;
    const bool tcp = space.mode != ProgramMode::Joints;
    const bool identity = corrector_.identity();
    const bool isArc = r_->motion == Motion::ArcCw || r_->motion == Motion::ArcCcw;
    const bool isRapid = r_->motion == Motion::Rapid && !r_->rapidIsFeed;
    const bool vector = space.mode == ProgramMode::TcpVector;
    bool outStartKnown = (outKnown_ & all_) == all_;
    const bool nomStartKnown = rec.nomStartKnown;
    const ProgramPoint& nomStart = rec.nomStart;
    const ProgramPoint& nomEnd = rec.nomEnd;
    const AxisVector& cNom = rec.cNom;
    const AxisVector& cEnd = rec.cEnd;
    if (vector) {
        outStartKnown = outStartKnown && (outVectorKnown_ || vectorOf(corrector_, outAt_, cNom));
        if (outStartKnown && !outVectorKnown_) {
            outVector_ = outAt_.vector;
            outVectorKnown_ = true;
        }
    }
    ++summary_.moves;
    if (tcp) ++summary_.tcpMoves;
    if (!identity) {
        summary_.maxTipResidual = std::max(summary_.maxTipResidual, rec.tipResidual);
        summary_.maxAxisResidual = std::max(summary_.maxAxisResidual, rec.axisResidual);
        if (rec.unconverged) ++summary_.unconverged;
        for (int a = 0; a < n; ++a) {
            const double d = std::fabs(cEnd[a] - cNom[a]);
            if (layout_.rotary[a]) {
                if (d > summary_.maxRotaryCorrection) summary_.maxRotaryCorrection = d, summary_.maxRotaryLine = no;
            } else if (d > summary_.maxLinearCorrection) {
                summary_.maxLinearCorrection = d, summary_.maxLinearLine = no;
            }
        }
    }
    if (rec.outsideTravel) ++summary_.outsideTravel;
    // Program position of the corrected end point (the nominal one when nothing was corrected).
    ProgramPoint qEnd = nomEnd;
    if (rec.corrected) corrector_.toProgram(space, cEnd, qEnd);

    // Pieces.
    pieces_.clear();
    SplitStats stats;
    bool arcKept = false, arcToLines = false;
    ArcFit fit;
    const AxisVector outStart = outPos_;
    PathContext ctx;
    ctx.space = space;
    ctx.outStart.p = outPos_;
    ctx.outStart.v = outVector_;
    ctx.guess = cNom;
    if (!identity && outStartKnown && nomStartKnown && offCourse_) {
        // The output starts off the corrected nominal start (a block before it was passed through, or TCP was just
        // switched on): splitting cannot remove that offset, so it is blended out along the move, not measured.
        AxisVector c0, cOut;
        if (corrector_.toJoints(space, nomStart, cNom, c0) && corrector_.toJoints(space, ctx.outStart, cNom, cOut)) {
            ctx.startOffset = corrector_.actualTip(cOut, space.toolLength) - corrector_.nominalTip(c0, space.toolLength);
            if (ctx.startOffset.norm() > options_.corrector.toleranceMm) ++summary_.offPathStarts;
        }
    }
    ctx.tolerance = identity ? options_.corrector.toleranceMm : toleranceFor(space, no);
    if (isArc) {
        if (!outStartKnown) {
            r_->reason = "arc from an output position that is not known";
            r_->report = true;
            --summary_.moves;
            passThrough(ln, no);
            return;
        }
        MovePath path = MovePath::arc(r_->start, r_->end, r_->arc);
        path.vector = vector;
        path.v0 = nomStart.v;
        path.v1 = nomEnd.v;
        const bool closed = std::hypot(r_->end[r_->arc.axis0] - r_->start[r_->arc.axis0],
                                       r_->end[r_->arc.axis1] - r_->start[r_->arc.axis1]) < 1e-12;
        if (closed && !identity) {
            // A full circle must end exactly where the controller starts it, digit for digit.
            qEnd.p[r_->arc.axis0] = outStart[r_->arc.axis0];
            qEnd.p[r_->arc.axis1] = outStart[r_->arc.axis1];
        }
        fit = corrector_.fitArc(path, ctx, qEnd, closed);
        if (fit.ok || r_->stop) {
            if (!fit.ok)
                notice(true, no, fmt::format("arc kept although {:.3f} um off the nominal path: the block holds a program stop",
                                             fit.maxDeviation / kUm));
            arcKept = true;
            summary_.maxPathDeviation = std::max(summary_.maxPathDeviation, fit.maxDeviation);
            pieces_.push_back({1.0, qEnd});
        } else {
            corrector_.splitArc(path, ctx, qEnd, pieces_, stats);
            arcToLines = true;
            ++summary_.arcsToLines;
        }
    } else {
        MovePath path = MovePath::line(r_->start, r_->end);
        path.vector = vector;
        path.v0 = nomStart.v;
        path.v1 = nomEnd.v;
        const bool measurable = nomStartKnown && outStartKnown && !identity;
        const bool subdivide = measurable && !isRapid && !r_->stop;
        if (measurable && !isRapid) corrector_.split(path, ctx, qEnd, subdivide, pieces_, stats);
        else pieces_.push_back({1.0, qEnd});
    }
    summary_.maxPathDeviation = std::max(summary_.maxPathDeviation, stats.maxDeviation);
    if (stats.limited) {
        ++summary_.limited;
        notice(true, no, fmt::format("tolerance not met after the subdivision limit ({:.3f} um left)", stats.maxDeviation / kUm));
    }
    const bool inverseTime = r_->feedMode == FeedMode::InverseTime;
    if (pieces_.size() > 1 && inverseTime && r_->feedWord < 0)
        notice(true, no, "inverse-time move without F split: the pieces carry no feed");

    // Piece 1 goes onto the original block.
    edits_.clear();
    const Motion pieceMotion = arcToLines ? Motion::Linear : r_->motion;
    if (r_->motionWord >= 0) {
        if (arcToLines) {
            const Word& g = b_->words[r_->motionWord];
            char t[4];
            size_t k = 0;
            if (g.digitsBefore >= 2) t[k++] = '0';
            t[k++] = '1';
            edits_.add(g.valueBegin, g.end, std::string_view(t, k));
        }
    } else if (outMotion_ != pieceMotion) {
        insertMotionWord(pieceMotion);
    }
    // Where new words go: after the last axis / centre / vector word, else after the motion word, else at the end
    // of the code.
    uint32_t insertPos = 0;
    bool anchor = false;
    for (int i = 0; i < b_->count; ++i) {
        const Word& w = b_->words[i];
        const char c = w.letter;
        if (layout_.axis(c) >= 0 || c == 'I' || c == 'J' || c == 'K' || c == 'R' || w.ext) {
            insertPos = std::max(insertPos, w.end);
            anchor = true;
        }
    }
    if (!anchor) insertPos = r_->motionWord >= 0 ? b_->words[r_->motionWord].end : b_->codeEnd;
    char text[BlockEdits::kArena / 4];
    size_t textLen = 0;
    static constexpr char kOrder[] = "XYZUVWABC";
    auto axesOf = [&](const ProgramPoint& q, bool onBlock, char* buf, size_t& used) {
        // Existing words in place; missing ones appended in X Y Z U V W A B C order (vector mode: no rotary words).
        auto one = [&](int a) {
            if (vector && layout_.rotary[a]) return;
            const int existing = onBlock ? r_->axisWord[a] : -1;
            char w[kMaxNumberChars + 16];
            size_t len = 0;
            bool replace = false;
            if (!axisWord(a, q.p[a], existing, w, len, replace)) return;
            if (replace && existing >= 0 && existing < b_->count) {
                replaceNumber(b_->words[static_cast<size_t>(existing)], w, len);
            } else {
                std::memcpy(buf + used, w, len);
                used += len;
            }
        };
        for (const char* p = kOrder; *p; ++p)
            if (const int a = layout_.axis(*p); a >= 0) one(a);
        for (int a = 0; a < n; ++a)
            if (!std::strchr(kOrder, layout_.letter[a])) one(a);  // axes with letters outside the usual set
        if (vector) vectorWords(q.v, onBlock, buf, used);
    };
    axesOf(pieces_[0].q, true, text, textLen);
    if (arcKept && !identity) arcWords(fit, outStart, insertPos);
    if (arcToLines) {
        for (int i = 0; i < b_->count; ++i) {
            const Word& w = b_->words[i];
            const bool centre = w.letter == 'I' || w.letter == 'J' || w.letter == 'K' || w.letter == 'R' ||
                                (w.letter == 'P' && dialect_ == Dialect::Rs274ngc);
            if (!centre || w.ext) continue;
            uint32_t begin = w.begin;
            if (begin > 0 && (ln.text[begin - 1] == ' ' || ln.text[begin - 1] == '\t')) --begin;
            edits_.add(begin, w.end, {});
        }
    }
    char num[kMaxNumberChars];
    double readBack, res;
    auto feedOf = [&](size_t k) {
        const double dt = pieces_[k].t - (k == 0 ? 0.0 : pieces_[k - 1].t);
        return r_->feed / std::max(dt, 1e-12);
    };
    if (inverseTime && pieces_.size() > 1 && r_->feedWord >= 0) {
        const Word& f = b_->words[r_->feedWord];
        const size_t k = number('F', false, feedOf(0), &f, num, readBack, res);
        edits_.add(f.valueBegin, f.end, std::string_view(num, k));
    }
    if (textLen > 0) edits_.add(insertPos, insertPos, std::string_view(text, textLen));
    if (edits_.overflow()) {
        r_->reason = "block too long to rewrite";
        r_->report = true;
        --summary_.moves;
        passThrough(ln, no);
        return;
    }
    const bool changed = !edits_.empty();
    if (changed) {
        edits_.apply(ln.text, out_);
        ++summary_.corrected;
    } else {
        out_.write(ln.text);
    }
    if (!ln.eol.empty()) lastEol_.assign(ln.eol);

    // Further pieces: new lines after the block, in its style.
    if (pieces_.size() > 1) {
        ++summary_.split;
        summary_.addedLines += pieces_.size() - 1;
        // Indentation and block delete of the original line.
        size_t indent = 0;
        while (indent < ln.text.size() && (ln.text[indent] == ' ' || ln.text[indent] == '\t')) ++indent;
        std::string_view prefix = ln.text.substr(0, indent);
        std::string_view skip;
        if (b_->blockDelete >= 0) {
            size_t e = static_cast<size_t>(b_->blockDelete) + 1;
            while (e < ln.text.size() && std::isdigit(static_cast<unsigned char>(ln.text[e]))) ++e;
            skip = ln.text.substr(static_cast<size_t>(b_->blockDelete), e - static_cast<size_t>(b_->blockDelete));
        }
        const Motion lineMotion = r_->motion == Motion::Rapid ? Motion::Rapid : Motion::Linear;
        for (size_t k = 1; k < pieces_.size(); ++k) {
            out_.write(ln.eol.empty() ? std::string_view(lastEol_) : ln.eol);
            char buf[1024];
            size_t used = 0;
            used += motionText(lineMotion, buf);
            axesOf(pieces_[k].q, false, buf, used);
            if (inverseTime && r_->feedWord >= 0) {
                const size_t fn = number('F', false, feedOf(k), &b_->words[r_->feedWord], num, readBack, res);
                used += composeWord('F', num, fn, 0, true, buf + used);
            }
            out_.write(prefix);
            out_.write(skip);
            out_.write(std::string_view(buf, used));
        }
    }
    out_.write(ln.eol);
    outMotion_ = arcToLines ? Motion::Linear : r_->motion;
    // Where the nominal and the output programs now are.
    outAt_ = Where{outStartKnown || (r_->absolute && !isArc), space, pieces_.back().q, cEnd, rec.jointsComputed && !isArc,
                 pieces_.back().q.v, vector};
    if (!vector) outVectorKnown_ = false;
    offCourse_ = false;
}

void ProgramCorrector::overlong(const Record& rec) {
    if (!rec.overlongCode) return;  // white space and comments only: nothing it could change
    ++summary_.blocks;
    ++summary_.passedThrough;
    const bool modal = rec.overlongModal;
    std::string axes;
    for (int a = 0; a < layout_.count; ++a)
        if (r_->words & (1u << a)) axes.push_back(layout_.letter[a]);
    if (modal) {
        outKnown_ = 0;
        outMotion_ = Motion::Unknown;
    } else {
        outKnown_ &= ~r_->words;
    }
    if (modal || r_->words) {
        outAt_.known = outVectorKnown_ = false;
        offCourse_ = true;
    }
    notice(false, rec.number,
           fmt::format("line longer than {} bytes: passed through unparsed; {}", options_.bufferSize,
                       modal ? "it holds codes that may change any mode: every position is unknown afterwards"
                             : axes.empty() ? "it names no axis: positions kept"
                                            : fmt::format("positions of {} unknown afterwards", axes)));
}

void ProgramCorrector::line(Record& rec) {
    const Line ln{rec.text, rec.eolView(), rec.number, rec.partial, rec.firstPiece, rec.lastPiece};
    const uint64_t no = ln.number;
    b_ = &rec.b;
    r_ = &rec.r;
    if (ln.firstPiece) ++summary_.lines;  // the pieces of an overlong line count as one line
    if (ln.eol.size() == 1 && ln.eol[0] == '\r' && !warnedCr_) {
        warnedCr_ = true;
        notice(true, no, "lines end with a lone CR (classic Mac OS line ends): read as line ends and kept");
    }
    if (ln.partial) {
        out_.write(ln.text);
        out_.write(ln.eol);
        if (ln.lastPiece) overlong(rec);
        return;
    }
    lineText_ = ln.text;
    updateStyles(*b_, ln.text);
    if (b_->count > 0) blockStyle(ln.text);
    warnings(no);
    for (auto& [warning, message] : rec.notices) notice(warning, no, std::move(message));
    // Axes taken at 0 until commanded are at 0 for the output controller too.
    if (const AxisMask fresh = rec.assumed & ~outKnown_) {
        for (int a = 0; a < layout_.count; ++a)
            if (fresh & (1u << a)) outPos_[a] = r_->start[a];
        outKnown_ |= fresh;
    }
    switch (r_->kind) {
        case BlockKind::Empty:
            out_.write(ln.text);
            out_.write(ln.eol);
            return;
        case BlockKind::NoMotion:
            ++summary_.blocks;
            out_.write(ln.text);
            out_.write(ln.eol);
            if (r_->motionCode) outMotion_ = r_->motion;
            if (r_->modeSwitch) switchMode();
            return;
        case BlockKind::PassThrough:
            ++summary_.blocks;
            if (rec.frontRefused && rec.space.mode != ProgramMode::Joints) ++summary_.tcpMoves;
            passThrough(ln, no);
            if (rec.forgetOutput) outKnown_ = 0;
            return;
        case BlockKind::Move:
            ++summary_.blocks;
            move(rec);
            return;
    }
}

/// Threads for a correction: --threads, or the machine's cores; two are used at most (front end and back end).
int threadsFor(const CorrectOptions& o) {
    if (o.threads > 0) return o.threads;
    return static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
}

/// The front end on its own thread, handing records to the back end (the calling thread) in batches, in program
/// order: the same computations as on one thread, so the same output byte for byte. Constant memory: a fixed number
/// of batches, each closed after kLines records or kBytes of text (a piece of an overlong line fills one alone).
class Pipeline {
public:
    static constexpr int kBatches = 4, kLines = 128;
    static constexpr size_t kBytes = size_t{256} << 10;

    Pipeline() {
        for (Batch& b : batches_) b.records.resize(kLines);
    }

    template <class Consume>
    void run(FrontEnd& front, Consume&& consume) {
        std::thread producer([&] { produce(front); });
        try {
            for (int i = 0;; i = (i + 1) % kBatches) {
                Batch& b = batches_[i];
                {
                    std::unique_lock lock(mutex_);
                    changed_.wait(lock, [&] { return b.full; });
                }
                for (size_t k = 0; k < b.count; ++k) {
                    consume(b.records[k]);
                    std::string& t = b.records[k].text;
                    if (t.capacity() > (size_t{64} << 10)) std::string().swap(t);  // a long line's buffer goes
                }
                const bool last = b.last;
                const std::exception_ptr error = b.error;
                {
                    std::lock_guard lock(mutex_);
                    b.full = b.last = false;
                    b.error = nullptr;
                }
                changed_.notify_all();
                if (error) std::rethrow_exception(error);
                if (last) break;
            }
        } catch (...) {
            {
                std::lock_guard lock(mutex_);
                abort_ = true;
            }
            changed_.notify_all();
            producer.join();
            throw;
        }
        producer.join();
    }

private:
    struct Batch {
        std::vector<Record> records;
        size_t count = 0;
        bool full = false, last = false;
        std::exception_ptr error;
    };

    void produce(FrontEnd& front) {
        for (int i = 0;; i = (i + 1) % kBatches) {
            Batch& b = batches_[i];
            {
                std::unique_lock lock(mutex_);
                changed_.wait(lock, [&] { return !b.full || abort_; });
                if (abort_) return;
            }
            b.count = 0;
            size_t bytes = 0;
            try {
                while (b.count < kLines && bytes < kBytes) {
                    Record& rec = b.records[b.count];
                    if (!front.next(rec)) {
                        b.last = true;
                        break;
                    }
                    bytes += rec.text.size();
                    ++b.count;
                }
            } catch (...) {
                b.error = std::current_exception();
                b.last = true;
            }
            const bool last = b.last;
            {
                std::lock_guard lock(mutex_);
                b.full = true;
            }
            changed_.notify_all();
            if (last) return;
        }
    }

    std::array<Batch, kBatches> batches_;
    std::mutex mutex_;
    std::condition_variable changed_;
    bool abort_ = false;
};

}  // namespace

CorrectSummary correctProgram(const MachineModel& machine, const DeviationSet& deviations, std::istream& in,
                              std::ostream& out, const CorrectOptions& given) {
    CorrectSummary s;
    LineReader reader(in, given.bufferSize);
    const std::string_view head = reader.head();
    checkTextHead(head, given.inputName);
    // No tool length given: a test program names the one it was made for in its header (cnccomp testprog).
    CorrectOptions withHeader;
    const std::optional<HeaderToolLength> header =
        given.setup.defaultToolLengthGiven ? std::nullopt : toolLengthFromHeader(head);
    if (header) {
        withHeader = given;
        withHeader.setup.defaultToolLength = header->mm;
        withHeader.setup.defaultToolLengthGiven = true;
    }
    const CorrectOptions& options = header ? withHeader : given;
    const auto noteHeader = [&](CorrectSummary& summary) {
        if (!header) return;
        summary.headerToolLength = header->mm;
        summary.headerToolLengthLine = header->line;
    };
    noteHeader(s);
    // HEIDENHAIN Klartext (BEGIN PGM among the first lines, whatever --dialect says): its own corrector.
    const int klartext = klartextHeaderLine(head);
    if (klartext > 0 || options.dialect == Dialect::Heidenhain) {
        if (klartext == 0)
            throw InputError(options.inputName, 0,
                             "--dialect heidenhain: no BEGIN PGM among the first lines, not a HEIDENHAIN Klartext program");
        CorrectSummary k = correctKlartextProgram(machine, deviations, reader, out, options);
        noteHeader(k);
        k.dialectDetected = !options.dialect || *options.dialect != Dialect::Heidenhain;
        k.dialectCertain = klartext > 0;
        k.dialectReason = "BEGIN PGM";
        return k;
    }
    if (options.dialect) {
        s.dialect = *options.dialect;
    } else {
        const DetectedDialect d = detectDialect(head);
        s.dialect = d.dialect;
        s.dialectDetected = true;
        s.dialectCertain = d.certain;
        s.dialectReason = d.reason;
    }
    OutputBuffer buffer(out);
    FrontEnd front(machine, deviations, options, s.dialect, reader);
    ProgramCorrector back(machine, deviations, options, s.dialect, s, buffer);
    auto consume = [&](Record& rec) {
        back.line(rec);
        if (options.progress && (rec.number & 0x1fff) == 0 && rec.lastPiece) options.progress(rec.bytesConsumed);
    };
    if (threadsFor(options) < 2) {
        Record rec;
        while (front.next(rec)) consume(rec);
    } else {
        Pipeline pipe;
        pipe.run(front, consume);
    }
    buffer.flush();
    if (options.progress) options.progress(reader.bytesConsumed());
    s.bytesIn = reader.bytesConsumed();
    s.bytesOut = buffer.bytesWritten();
    return s;
}

std::string formatSummary(const CorrectSummary& s, size_t maxListed) {
    std::string t;
    t += fmt::format("dialect: {}{}\n", dialectName(s.dialect),
                     s.dialectDetected ? fmt::format(" (detected: {}{})", s.dialectReason,
                                                     s.dialectCertain ? "" : "; use --dialect to choose")
                                       : std::string());
    t += fmt::format("blocks read: {} ({} lines, {} bytes in, {} bytes out)\n", s.blocks, s.lines, s.bytesIn, s.bytesOut);
    t += fmt::format("moves evaluated: {}; blocks corrected: {}; moves split: {} (+{} lines, {} arcs into lines)\n",
                     s.moves, s.corrected, s.split, s.addedLines, s.arcsToLines);
    t += fmt::format("passed through unchanged: {} ({} of them ordinary uncorrected moves: G53, reference returns)\n",
                     s.passedThrough, s.notCorrected);
    t += fmt::format("largest correction: {:.3f} um linear (line {}), {:.3f} arcsec rotary (line {})\n",
                     s.maxLinearCorrection / kUm, s.maxLinearLine, s.maxRotaryCorrection / kArcsec, s.maxRotaryLine);
    t += fmt::format("largest residual: {:.2g} um at endpoints, {:.3f} um on the path (checked midpoints), tool axis {:.3f} arcsec\n",
                     s.maxTipResidual / kUm, s.maxPathDeviation / kUm, s.maxAxisResidual / kArcsec);
    if (s.headerToolLengthLine)
        t += fmt::format("tool length: {:g} mm, from the program's header (line {}: cnccomp correct --tool-length {:g})\n",
                         s.headerToolLength, s.headerToolLengthLine, s.headerToolLength);
    if (s.tcpMoves) t += fmt::format("moves in tool-tip (TCP) mode: {}\n", s.tcpMoves);
    if (s.unconverged) t += fmt::format("endpoints not converged (left unchanged): {}\n", s.unconverged);
    if (s.limited) t += fmt::format("moves over the tolerance after the subdivision limit: {}\n", s.limited);
    if (s.outsideTravel) t += fmt::format("moves outside the travel of an axis: {} (see the warnings)\n", s.outsideTravel);
    if (s.clampedTolerance)
        t += fmt::format("tolerance raised to {:.3g} um on {} moves: the written digits cannot hold less\n",
                         s.toleranceFloor / kUm, s.clampedTolerance);
    if (s.offPathStarts)
        t += fmt::format("moves starting off the nominal path after a block passed through: {} (offset blended out, "
                         "not split for)\n",
                         s.offPathStarts);
    if (!s.passThrough.empty()) {
        t += "not evaluated (passed through):\n";
        for (size_t i = 0; i < s.passThrough.size() && i < maxListed; ++i)
            t += fmt::format("  line {}: {}\n", s.passThrough[i].line, s.passThrough[i].message);
        const uint64_t listed = std::min<uint64_t>(s.passThrough.size(), maxListed);
        const uint64_t reported = s.passedThrough - s.notCorrected;
        if (reported > listed) t += fmt::format("  … and {} more (--report FILE lists all)\n", reported - listed);
    }
    if (!s.warnings.empty()) {
        t += "warnings:\n";
        for (size_t i = 0; i < s.warnings.size() && i < maxListed; ++i)
            t += fmt::format("  line {}: {}\n", s.warnings[i].line, s.warnings[i].message);
        if (s.warningCount > std::min<uint64_t>(s.warnings.size(), maxListed))
            t += fmt::format("  … and {} more\n", s.warningCount - std::min<uint64_t>(s.warnings.size(), maxListed));
    }
    return t;
}

}  // namespace cnccomp::pp
