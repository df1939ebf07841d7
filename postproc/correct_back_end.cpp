// The back end's path work: pass-through, mode switches, the tolerance, a move checked and split, a line written.
#include "postproc/correct_back_end.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "postproc/correct_move.hpp"

namespace cnccomp::postproc::iso {
using namespace cnccomp::io;

namespace {

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

}  // namespace

void ProgramCorrector::notice(bool warning, uint64_t line, std::string message) {
    addNotice(summary_, options_.report, warning, line, std::move(message));
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
    lastEnd_.valid = false;
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
    const AxisMask rotary = layout_.rotaryAxes();
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
    const Line ln{rec.text, rec.eolView(), rec.number, false, true, true};
    const uint64_t no = rec.number;
    const MoveSpace space = rec.space;
    const bool tcp = space.mode != ProgramMode::Joints;
    const bool identity = corrector_.identity();
    const bool vector = space.mode == ProgramMode::TcpVector;
    bool outStartKnown = (outKnown_ & all_) == all_;
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
        countCorrection(summary_, layout_, cNom, cEnd, no);
    }
    if (rec.outsideTravel) ++summary_.outsideTravel;
    // Program position of the corrected end point (the nominal one when nothing was corrected).
    ProgramPoint qEnd = nomEnd;
    if (rec.corrected) corrector_.toProgram(space, cEnd, qEnd);

    MovePieces pieces;
    pieces.outStartKnown = outStartKnown;
    if (!findPieces(rec, qEnd, pieces)) {
        r_->reason = "arc from an output position that is not known";
        r_->report = true;
        --summary_.moves;
        passThrough(ln, no);
        return;
    }
    writeMove(rec, ln, pieces);
}

bool ProgramCorrector::findPieces(const Record& rec, ProgramPoint qEnd, MovePieces& p) {
    const uint64_t no = rec.number;
    const MoveSpace space = rec.space;
    const bool identity = corrector_.identity();
    const bool isArc = r_->motion == Motion::ArcCw || r_->motion == Motion::ArcCcw;
    const bool isRapid = r_->motion == Motion::Rapid && !r_->rapidIsFeed;
    const bool vector = space.mode == ProgramMode::TcpVector;
    const bool outStartKnown = p.outStartKnown, nomStartKnown = rec.nomStartKnown;
    const ProgramPoint& nomStart = rec.nomStart;
    const ProgramPoint& nomEnd = rec.nomEnd;
    const AxisVector& cNom = rec.cNom;
    pieces_.clear();
    SplitStats stats;
    bool& arcKept = p.arcKept;
    bool& arcToLines = p.arcToLines;
    ArcFit& fit = p.fit;
    p.outStart = outPos_;
    const AxisVector& outStart = p.outStart;
    PathContext ctx;
    ctx.space = space;
    ctx.outStart.p = outPos_;
    ctx.outStart.v = outVector_;
    ctx.guess = cNom;
    if (!identity && outStartKnown && nomStartKnown && offCourse_)
        blendStartOffset(corrector_, nomStart, options_.corrector.toleranceMm, ctx, summary_);
    ctx.tolerance = identity ? options_.corrector.toleranceMm : toleranceFor(space, no);
    if (isArc) {
        if (!outStartKnown) return false;
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
        const MidpointBound& bound = corrector_.midpointBound();
        p.endBounded = bound.usable() && rec.corrected && space.mode == ProgramMode::TcpAngles;
        if (p.endBounded)
            p.endBound = bound.endBound(rec.tipResidual, rec.cEnd, space.toolLength, options_.corrector.solveTolerance);
        if (measurable && !isRapid) {
            if (p.endBounded) {
                ctx.midpointBound = currentMidpointBound(rec, ctx, qEnd, p.endBound);
                ctx.largestMeasured = summary_.maxPathDeviation;
            }
            corrector_.split(path, ctx, qEnd, subdivide, pieces_, stats);
        }
        else pieces_.push_back({1.0, qEnd});
    }
    countPath(stats, summary_, options_.report, no);
    const bool inverseTime = r_->feedMode == FeedMode::InverseTime;
    if (pieces_.size() > 1 && inverseTime && r_->feedWord < 0)
        notice(true, no, "inverse-time move without F split: the pieces carry no feed");
    return true;
}

double ProgramCorrector::currentMidpointBound(const Record& rec, const PathContext& ctx, const ProgramPoint& qEnd,
                                              double endBound) const {
    // The bound's premises (midpoint_bound.hpp): the move starts where the last corrected one ended (the same
    // nominal point, the output's digits of its corrected end, no offset to blend out) in the same space.
    const MoveSpace& s = rec.space;
    if (!lastEnd_.valid || offCourse_ || lastEnd_.space.mode != s.mode || lastEnd_.space.toolLength != s.toolLength ||
        lastEnd_.space.controlLength != s.controlLength)
        return HUGE_VAL;
    for (int a = 0; a < layout_.count; ++a)
        if (!(r_->start[a] == lastEnd_.nominal[a])) return HUGE_VAL;
    return corrector_.midpointBound().midpoint(s.toolLength, s.controlLength, ctx.outStart.p, qEnd.p, r_->start,
                                               r_->end, lastEnd_.corrected, lastEnd_.bound, endBound);
}

void ProgramCorrector::writeMove(const Record& rec, const Line& ln, const MovePieces& p) {
    const int n = layout_.count;
    const uint64_t no = rec.number;
    const MoveSpace space = rec.space;
    const bool identity = corrector_.identity();
    const bool isArc = r_->motion == Motion::ArcCw || r_->motion == Motion::ArcCcw;
    const bool vector = space.mode == ProgramMode::TcpVector;
    const bool inverseTime = r_->feedMode == FeedMode::InverseTime;
    const bool arcKept = p.arcKept, arcToLines = p.arcToLines, outStartKnown = p.outStartKnown;
    const ArcFit& fit = p.fit;
    const AxisVector& outStart = p.outStart;
    const AxisVector& cEnd = rec.cEnd;
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
                copyBytes(buf + used, w, len);
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
    lastEnd_.valid = p.endBounded;  // set for straight moves only (findPieces)
    if (lastEnd_.valid) {
        lastEnd_.space = space;
        lastEnd_.corrected = pieces_.back().q.p;
        lastEnd_.nominal = r_->end;
        lastEnd_.bound = p.endBound;
    }
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
        lastEnd_.valid = false;
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
    if (r_->kind != BlockKind::Move && r_->kind != BlockKind::Empty) lastEnd_.valid = false;
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

}  // namespace cnccomp::postproc::iso
