#include "postproc/klartext_correct.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <ostream>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "postproc/block_writer.hpp"
#include "postproc/correct_move.hpp"
#include "postproc/correction.hpp"
#include "postproc/klartext_blocks.hpp"
#include "cnccomp/io/number_format.hpp"

namespace cnccomp::postproc {
using namespace cnccomp::io;
namespace {

constexpr char kKlartextAxisOrder[] = "XYZUVWABC";

class KlartextCorrector {
public:
    KlartextCorrector(const MachineModel& m, const DeviationSet& d, const CorrectOptions& o, CorrectSummary& s,
                      OutputBuffer& out)
        : options_(o),
          layout_(AxisLayout::fromMachine(m)),
          corrector_(m, d, o.corrector),
          interp_(layout_, o.setup, o.inputName),
          summary_(s),
          out_(out),
          endPoints_(layout_.count),
          travel_(m, layout_) {
        all_ = layout_.all();
        for (int a = 0; a < layout_.count; ++a) {
            if (layout_.rotary[a]) rotary_ |= 1u << a, ++rotaryCount_;
            else ++linearCount_;
        }
        outPos_ = interp_.position();
        outKnown_ = interp_.known();
        decimals_.fill(-1);
        pieces_.reserve(static_cast<size_t>(o.corrector.maxPieces) + 4);
        interp_.setConverter([this](ProgramMode from, ProgramMode to, double lc, AxisVector& pos, AxisMask known) {
            return convert(from, to, lc, pos, known);
        });
    }

    void run(LineReader& reader);

private:
    AxisMask convert(ProgramMode from, ProgramMode to, double lc, AxisVector& pos, AxisMask known) {
        if ((known & all_) != all_ || (from != ProgramMode::Joints && !corrector_.tcp().supported()) ||
            (to != ProgramMode::Joints && !corrector_.tcp().supported()))
            return known & rotary_;
        AxisVector c;
        ProgramPoint p{pos, Vec3(0, 0, -1)};
        if (!corrector_.toJoints(MoveSpace{from, lc, lc}, p, pos, c)) return known & rotary_;
        corrector_.toProgram(MoveSpace{to, lc, lc}, c, p);
        pos = p.p;
        return all_;
    }
    void block();
    void overlong(const Line& ln);
    void notice(bool warning, uint64_t line, std::string message);
    void updateStyles();
    void renumber();
    void writeBlock();
    void passThrough(const char* why, bool report);
    void outputAfterPassThrough();
    void move();
    double toleranceFor(const MoveSpace& space);
    int decimalsFor(int a) const;
    size_t number(int a, double pv, char* out, double& readBack, double& res) const;
    bool axisWord(int a, double q, const KlartextAxisWord* orig, char* text, size_t& len);
    void wordsOnBlock(const ProgramPoint& q, bool rewrite);
    std::string pieceWords(const ProgramPoint& q);
    std::string_view tokenText(int i) const {
        const KlartextToken& t = b_.tokens[static_cast<size_t>(i)];
        return std::string_view(raw_).substr(t.begin, t.end - t.begin);
    }
    void dropToken(int i);

    const CorrectOptions& options_;
    AxisLayout layout_;
    Corrector corrector_;
    KlartextInterpreter interp_;
    CorrectSummary& summary_;
    OutputBuffer& out_;
    AxisMask all_ = 0, rotary_ = 0;
    int rotaryCount_ = 0, linearCount_ = 0;
    // The current logical block.
    std::string raw_, finalEol_, lastEol_ = "\n";
    uint64_t line_ = 0;
    KlartextBlock b_;
    BlockEdits edits_;
    // Style of the program's numbers.
    std::array<int, 26> decimals_{};
    bool fixed_ = false;
    // The output program: position in program space (read back from the written digits).
    AxisVector outPos_;
    AxisMask outKnown_ = 0;
    bool offCourse_ = true;
    // The end points (each from the previous one's correction) and the guesses of the nominal joints.
    EndPointSolver endPoints_;
    TravelCheck travel_;
    AxisVector nomJoints_;
    bool nomJointsValid_ = false;
    std::vector<Piece> pieces_;
    int64_t shift_ = 0;  ///< blocks inserted so far: added to every later leading block number
    bool warnedTolerance_ = false, warnedCr_ = false;
    bool wordEdits_ = false;  ///< the current block's words changed (not only its number)
};

void KlartextCorrector::notice(bool warning, uint64_t line, std::string message) {
    addNotice(summary_, options_.report, warning, line, std::move(message));
}

void KlartextCorrector::run(LineReader& reader) {
    Line ln;
    bool pending = false;
    while (reader.next(ln)) {
        if (ln.partial) {
            if (pending) {  // a block continued with '~' ends before a line too long to read
                block();
                pending = false;
            }
            overlong(ln);
            continue;
        }
        ++summary_.lines;
        if (ln.eol.size() == 1 && ln.eol[0] == '\r' && !warnedCr_) {
            warnedCr_ = true;
            notice(true, ln.number, "lines end with a lone CR (classic Mac OS line ends): read as line ends and kept");
        }
        if (ln.text.find('\0') != std::string_view::npos)
            throw InputError(options_.inputName, static_cast<int>(ln.number), "binary data in a Klartext program");
        if (!pending) {
            raw_.clear();
            line_ = ln.number;
        } else {
            raw_.append(finalEol_);
        }
        raw_.append(ln.text);
        finalEol_.assign(ln.eol);
        if (!ln.eol.empty()) lastEol_.assign(ln.eol);
        size_t e = ln.text.size();
        while (e > 0 && std::isspace(static_cast<unsigned char>(ln.text[e - 1]))) --e;
        pending = e > 0 && ln.text[e - 1] == '~';  // continued on the next line (also after a comment)
        if (!pending) block();
        if (options_.progress && (ln.number & 0x1fff) == 0) options_.progress(reader.bytesConsumed());
    }
    if (pending) block();
}

void KlartextCorrector::overlong(const Line& ln) {
    // Passed through unparsed; the leading block number still follows the renumbering.
    std::string_view text = ln.text;
    if (ln.firstPiece) {
        ++summary_.lines;
        size_t i = 0;
        while (i < text.size() && (text[i] == ' ' || text[i] == '\t')) ++i;
        size_t j = i;
        while (j < text.size() && std::isdigit(static_cast<unsigned char>(text[j]))) ++j;
        uint64_t no = 0;
        if (shift_ != 0 && j > i && j < text.size() && klartextBlockNumber(text.substr(i, j - i), no)) {
            out_.write(text.substr(0, i));
            out_.write(std::to_string(static_cast<int64_t>(no) + shift_));
            text.remove_prefix(j);
        }
    }
    out_.write(text);
    out_.write(ln.eol);
    if (!ln.lastPiece) return;
    ++summary_.blocks;
    ++summary_.passedThrough;
    interp_.forgetAll();
    outKnown_ = 0;
    offCourse_ = true;
    nomJointsValid_ = false;
    notice(false, ln.number,
           fmt::format("line longer than {} bytes: passed through unparsed; every position is unknown afterwards",
                       options_.bufferSize));
}

void KlartextCorrector::updateStyles() {
    for (const KlartextAxisWord& w : b_.axes) {
        const KlartextToken& t = b_.tokens[static_cast<size_t>(w.token)];
        const std::string_view num = std::string_view(raw_).substr(w.numberBegin, t.end - w.numberBegin);
        const size_t dot = num.find('.');
        const int d = dot == std::string_view::npos ? 0 : static_cast<int>(num.size() - dot - 1);
        const int letter = layout_.letter[w.axis] - 'A';
        decimals_[letter] = std::max(decimals_[letter], d);
        if (d > 0 && num.back() == '0') fixed_ = true;
    }
}

void KlartextCorrector::renumber() {
    if (shift_ == 0 || b_.numberToken < 0) return;
    uint64_t no = 0;
    if (!klartextBlockNumber(tokenText(b_.numberToken), no)) return;
    const KlartextToken& t = b_.tokens[static_cast<size_t>(b_.numberToken)];
    edits_.add(t.begin, t.end, std::to_string(static_cast<int64_t>(no) + shift_));
}

void KlartextCorrector::writeBlock() {
    if (edits_.empty()) out_.write(raw_);
    else edits_.apply(raw_, out_);
}

void KlartextCorrector::block() {
    interp_.interpret(raw_, line_, b_);
    edits_.clear();
    renumber();
    if (b_.kind != KlartextKind::Empty) ++summary_.blocks;
    updateStyles();
    switch (b_.kind) {
        case KlartextKind::Empty:
        case KlartextKind::NoMotion:
            if (b_.modeSwitch) {
                // The machine stays; the output's numbers are read in the new mode (as the nominal ones were).
                const ProgramMode to = interp_.mode();
                const ProgramMode from = to == ProgramMode::Joints ? ProgramMode::TcpAngles : ProgramMode::Joints;
                outKnown_ = convert(from, to, b_.controlLength, outPos_, outKnown_);
                offCourse_ = true;
            }
            writeBlock();
            out_.write(finalEol_);
            return;
        case KlartextKind::Unsupported:
            ++summary_.passedThrough;
            notice(false, line_, b_.reason + "; passed through");
            outKnown_ &= ~b_.words;
            if (b_.words) offCourse_ = true, nomJointsValid_ = false;
            if (interp_.mode() == ProgramMode::Joints && b_.mode != ProgramMode::Joints) outKnown_ &= rotary_;
            writeBlock();
            out_.write(finalEol_);
            return;
        case KlartextKind::Move: move(); return;
    }
}

void KlartextCorrector::outputAfterPassThrough() {
    for (const KlartextAxisWord& w : b_.axes) {
        const int a = w.axis;
        const AxisMask bit = 1u << a;
        if (!(b_.endKnown & bit)) {
            outKnown_ &= ~bit;
        } else if (!w.incremental) {
            outPos_[a] = b_.end[a];
            outKnown_ |= bit;
        } else if ((outKnown_ & bit) && (b_.startKnown & bit)) {
            outPos_[a] += b_.end[a] - b_.start[a];
        } else {
            outKnown_ &= ~bit;
        }
    }
    outKnown_ &= b_.endKnown;
    offCourse_ = true;
    nomJointsValid_ = false;
}

void KlartextCorrector::passThrough(const char* why, bool report) {
    ++summary_.passedThrough;
    if (!report) ++summary_.notCorrected;
    else notice(false, line_, why);
    writeBlock();
    out_.write(finalEol_);
    outputAfterPassThrough();
    if (b_.tcpOffAtEnd) outKnown_ = convert(ProgramMode::TcpAngles, ProgramMode::Joints, b_.controlLength, outPos_, outKnown_);
}

int KlartextCorrector::decimalsFor(int a) const {
    if (options_.decimals >= 0) return options_.decimals;
    const int floor = layout_.rotary[a] ? 4 : (interp_.inch() ? 5 : 4);
    return std::max(decimals_[layout_.letter[a] - 'A'], floor);
}

double KlartextCorrector::toleranceFor(const MoveSpace& space) {
    const double tol = options_.corrector.toleranceMm;
    int linDecimals = 15, rotDecimals = 15;
    for (int a = 0; a < layout_.count; ++a) {
        if (layout_.rotary[a]) rotDecimals = std::min(rotDecimals, decimalsFor(a));
        else linDecimals = std::min(linDecimals, decimalsFor(a));
    }
    const double floor = digitsTolerance(corrector_, space, b_.end, linDecimals, rotDecimals, interp_.inch(),
                                         linearCount_, rotaryCount_);
    return toleranceWithin(tol, floor, linDecimals, summary_, options_.report, line_, warnedTolerance_);
}

size_t KlartextCorrector::number(int a, double pv, char* out, double& readBack, double& res) const {
    NumberStyle st;
    st.decimals = decimalsFor(a);
    st.fixed = fixed_;
    st.plus = true;  // Klartext's signed style: X+12.5, X-3
    readBack = roundToStyle(pv, st);
    res = tenTo(-std::clamp(st.decimals, 0, 15));
    size_t n = formatNumber(pv, st, out);
    if (n > 0 && out[n - 1] == '.') --n;  // "+12." → "+12"
    return n;
}

bool KlartextCorrector::axisWord(int a, double q, const KlartextAxisWord* orig, char* text, size_t& len) {
    const AxisMask bit = 1u << a;
    const bool absolute = !orig || !orig->incremental;
    const double scale = b_.scale[a], off = b_.offset[a];
    len = 0;
    if (!absolute && !(outKnown_ & bit)) return false;  // incremental from an unknown output position: kept
    const double pv = absolute ? (q - off) / scale : (q - outPos_[a]) / scale;
    char num[kMaxNumberChars];
    double readBack = 0, res = 0;
    const size_t n = number(a, pv, num, readBack, res);
    if (orig) {
        if (std::fabs(pv - orig->value) < 0.5 * res) {
            // The correction does not show at this resolution: the program's bytes stay.
            if (absolute) outPos_[a] = orig->value * scale + off;
            else outPos_[a] += orig->value * scale;
            outKnown_ |= bit;
            return false;
        }
    } else if (outKnown_ & bit) {
        // A word the block does not have is added only for a change of one output digit at least.
        const double held = (outPos_[a] - off) / scale;
        if (std::fabs(pv - held) < res * (1.0 - 1e-9)) return false;
    }
    if (absolute) outPos_[a] = readBack * scale + off;
    else outPos_[a] += readBack * scale;
    outKnown_ |= bit;
    if (orig) {
        std::memcpy(text, num, n);
        len = n;
    } else {
        text[len++] = layout_.letter[a];
        std::memcpy(text + len, num, n);
        len += n;
    }
    return true;
}

void KlartextCorrector::dropToken(int i) {
    const KlartextToken& t = b_.tokens[static_cast<size_t>(i)];
    uint32_t begin = t.begin;
    while (begin > 0 && (raw_[begin - 1] == ' ' || raw_[begin - 1] == '\t')) --begin;
    edits_.add(begin, t.end, {});
}

void KlartextCorrector::wordsOnBlock(const ProgramPoint& q, bool rewrite) {
    char w[kMaxNumberChars + 8];
    size_t len = 0;
    const KlartextToken& key = b_.tokens[static_cast<size_t>(b_.keyToken)];
    wordEdits_ = false;
    if (rewrite) {
        wordEdits_ = true;
        // A circle or polar line becomes "L" with absolute words right after the keyword.
        edits_.add(key.begin, key.end, "L");
        for (int t : b_.dropTokens) dropToken(t);
        for (const KlartextAxisWord& aw : b_.axes) dropToken(aw.token);
        // Every axis the old words named is written (its output position is re-read); the others where they change.
        for (const KlartextAxisWord& aw : b_.axes) outKnown_ &= ~(1u << aw.axis);
        for (const char* p = kKlartextAxisOrder; *p; ++p) {
            const int a = layout_.axis(*p);
            if (a < 0 || !axisWord(a, q.p[a], nullptr, w + 1, len)) continue;
            w[0] = ' ';
            edits_.add(key.end, key.end, std::string_view(w, len + 1));
        }
        return;
    }
    const auto rank = [](char letter) {
        const char* p = std::strchr(kKlartextAxisOrder, letter);
        return p ? static_cast<int>(p - kKlartextAxisOrder) : 99;
    };
    uint32_t after = key.end;
    for (const KlartextAxisWord& aw : b_.axes) after = std::max(after, b_.tokens[static_cast<size_t>(aw.token)].end);
    for (const char* p = kKlartextAxisOrder; *p; ++p) {
        const int a = layout_.axis(*p);
        if (a < 0) continue;
        const KlartextAxisWord* orig = nullptr;
        for (const KlartextAxisWord& aw : b_.axes)
            if (aw.axis == a) orig = &aw;
        if (!axisWord(a, q.p[a], orig, w + 1, len)) continue;
        wordEdits_ = true;
        if (orig) {
            const KlartextToken& t = b_.tokens[static_cast<size_t>(orig->token)];
            edits_.add(orig->numberBegin, t.end, std::string_view(w + 1, len));
            continue;
        }
        // A new word: before the first word of a later axis (keeping X Y Z … A B C order), else after the last one.
        const KlartextAxisWord* later = nullptr;
        for (const KlartextAxisWord& aw : b_.axes)
            if (rank(layout_.letter[aw.axis]) > rank(*p) &&
                (!later || b_.tokens[static_cast<size_t>(aw.token)].begin < b_.tokens[static_cast<size_t>(later->token)].begin))
                later = &aw;
        if (later) {
            w[len + 1] = ' ';
            edits_.add(b_.tokens[static_cast<size_t>(later->token)].begin, b_.tokens[static_cast<size_t>(later->token)].begin,
                       std::string_view(w + 1, len + 1));
        } else {
            w[0] = ' ';
            edits_.add(after, after, std::string_view(w, len + 1));
        }
    }
}

std::string KlartextCorrector::pieceWords(const ProgramPoint& q) {
    std::string s;
    char w[kMaxNumberChars + 8];
    size_t len = 0;
    for (const char* p = kKlartextAxisOrder; *p; ++p) {
        const int a = layout_.axis(*p);
        if (a < 0 || !axisWord(a, q.p[a], nullptr, w, len)) continue;
        s.push_back(' ');
        s.append(w, len);
    }
    return s;
}

void KlartextCorrector::move() {
    if (b_.tcpOnAtStart) outKnown_ = convert(ProgramMode::Joints, ProgramMode::TcpAngles, b_.controlLength, outPos_, outKnown_);
    const MoveSpace space{b_.mode, b_.controlLength, b_.tipLength};
    const bool tcp = space.mode != ProgramMode::Joints;
    const bool isArc = b_.motion == Motion::ArcCw || b_.motion == Motion::ArcCcw;
    const bool rapid = b_.motion == Motion::Rapid;
    if (b_.machine) return passThrough("M91/M92 (machine coordinates)", false);
    if ((b_.endKnown & all_) != all_) {
        std::string axes;
        for (const char* p = kKlartextAxisOrder; *p; ++p)
            if (const int a = layout_.axis(*p); a >= 0 && !(b_.endKnown & (1u << a))) axes += (axes.empty() ? "" : " ") + std::string(1, *p);
        const std::string why = fmt::format("position of axis {} not known yet", axes);
        return passThrough(why.c_str(), true);
    }
    if (isArc && !b_.arcKnown) return passThrough("circle whose start or centre is not known", true);
    if (tcp && !corrector_.tcp().supported()) return passThrough(corrector_.tcp().why(), true);
    const bool identity = corrector_.identity();
    if (identity) {
        // Nothing to correct: every byte stays (no block is inserted, so no number changes either).
        ++summary_.moves;
        if (tcp) ++summary_.tcpMoves;
        writeBlock();
        out_.write(finalEol_);
        outPos_ = b_.end;
        outKnown_ = b_.endKnown;
        if (b_.tcpOffAtEnd) outKnown_ = convert(ProgramMode::TcpAngles, ProgramMode::Joints, b_.controlLength, outPos_, outKnown_);
        return;
    }
    ProgramPoint nomEnd{b_.end, Vec3(0, 0, -1)}, nomStart{b_.start, Vec3(0, 0, -1)};
    const AxisVector guess = nomJointsValid_ ? nomJoints_ : b_.end;
    AxisVector cNom, cEnd;
    NominalPose nomPose;
    if (!corrector_.toJoints(space, nomEnd, guess, cNom, &nomPose))
        return passThrough("the controller's TCP kinematics cannot reach this position", true);
    ++summary_.moves;
    if (tcp) ++summary_.tcpMoves;
    const EndPointSolver::Result s =
        endPoints_.solve(corrector_, layout_, options_, space.toolLength, cNom, &nomPose, {b_.tipLengthAssumed, line_}, cEnd);
    const bool corrected = s.corrected;
    summary_.maxTipResidual = std::max(summary_.maxTipResidual, s.tipResidual);
    summary_.maxAxisResidual = std::max(summary_.maxAxisResidual, s.axisResidual);
    if (s.unconverged) {
        ++summary_.unconverged;
        notice(true, line_, s.failure);
    }
    if (travel_.check(cNom, cEnd, [&](std::string message) { notice(true, line_, std::move(message)); }))
        ++summary_.outsideTravel;
    countCorrection(summary_, layout_, cNom, cEnd, line_);
    nomJoints_ = cNom;
    nomJointsValid_ = true;
    ProgramPoint qEnd = nomEnd;
    if (corrected) corrector_.toProgram(space, cEnd, qEnd);

    const bool outStartKnown = (outKnown_ & all_) == all_;
    const bool nomStartKnown = (b_.startKnown & all_) == all_;
    pieces_.clear();
    SplitStats stats;
    PathContext ctx;
    ctx.space = space;
    ctx.outStart.p = outPos_;
    ctx.guess = cNom;
    if (outStartKnown && nomStartKnown && offCourse_)
        blendStartOffset(corrector_, nomStart, options_.corrector.toleranceMm, ctx, summary_);
    ctx.tolerance = toleranceFor(space);
    if (isArc) {
        if (!outStartKnown) {
            --summary_.moves;
            if (tcp) --summary_.tcpMoves;
            return passThrough("circle from an output position that is not known", true);
        }
        const MovePath path = MovePath::arc(b_.start, b_.end, b_.arc);
        corrector_.splitArc(path, ctx, qEnd, pieces_, stats);
        ++summary_.arcsToLines;
    } else {
        const MovePath path = MovePath::line(b_.start, b_.end);
        const bool measurable = nomStartKnown && outStartKnown;
        const bool subdivide = measurable && !rapid && !b_.hasM;
        if (measurable && !rapid) {
            corrector_.split(path, ctx, qEnd, subdivide, pieces_, stats);
            if (!subdivide && stats.maxDeviation > ctx.tolerance)
                notice(true, line_, fmt::format("not split although {:.3f} um off the nominal path at its midpoint: the block "
                                                "holds M functions",
                                                stats.maxDeviation / kUm));
        } else {
            pieces_.push_back({1.0, qEnd});
        }
    }
    countPath(stats, summary_, options_.report, line_);
    // Piece 1 on the block itself.
    const bool rewrite = isArc || b_.polar;
    wordsOnBlock(pieces_[0].q, rewrite);
    if (edits_.overflow()) {
        --summary_.moves;
        if (tcp) --summary_.tcpMoves;
        edits_.clear();
        renumber();
        return passThrough("block too long to rewrite", true);
    }
    if (wordEdits_ || pieces_.size() > 1) ++summary_.corrected;
    writeBlock();
    if (pieces_.size() > 1) {
        ++summary_.split;
        summary_.addedLines += pieces_.size() - 1;
        size_t indent = 0;
        while (indent < raw_.size() && (raw_[indent] == ' ' || raw_[indent] == '\t')) ++indent;
        const std::string_view prefix = std::string_view(raw_).substr(0, indent);
        uint64_t no = 0;
        const bool numbered = b_.numberToken >= 0 && klartextBlockNumber(tokenText(b_.numberToken), no);
        const std::string comp = b_.radiusCompToken >= 0 ? " " + std::string(tokenText(b_.radiusCompToken)) : std::string();
        for (size_t k = 1; k < pieces_.size(); ++k) {
            out_.write(finalEol_.empty() ? std::string_view(lastEol_) : std::string_view(finalEol_));
            out_.write(prefix);
            if (numbered) out_.write(fmt::format("{} ", static_cast<int64_t>(no) + shift_ + static_cast<int64_t>(k)));
            out_.write("L");
            out_.write(pieceWords(pieces_[k].q));
            out_.write(comp);
            out_.write(" ");
            out_.write(kKlartextInsertedComment);
        }
        if (numbered) shift_ += static_cast<int64_t>(pieces_.size() - 1);
    }
    out_.write(finalEol_);
    offCourse_ = false;
    if (b_.tcpOffAtEnd) {
        outKnown_ = convert(ProgramMode::TcpAngles, ProgramMode::Joints, b_.controlLength, outPos_, outKnown_);
        offCourse_ = true;
    }
}

}  // namespace

CorrectSummary correctKlartextProgram(const MachineModel& machine, const DeviationSet& deviations, LineReader& reader,
                                      std::ostream& out, const CorrectOptions& options) {
    CorrectSummary s;
    s.dialect = Dialect::Heidenhain;
    OutputBuffer buffer(out);
    KlartextCorrector k(machine, deviations, options, s, buffer);
    k.run(reader);
    finishCorrection(buffer, reader, options, s);
    return s;
}

}  // namespace cnccomp::postproc
