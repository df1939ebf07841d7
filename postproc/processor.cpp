#include "postproc/processor.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <istream>
#include <ostream>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "postproc/block_writer.hpp"
#include "postproc/line_reader.hpp"
#include "postproc/number_format.hpp"

namespace cnccomp::pp {

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

class ProgramCorrector {
public:
    ProgramCorrector(const MachineModel& m, const DeviationSet& d, const CorrectOptions& o, Dialect dialect,
                     CorrectSummary& s, OutputBuffer& out)
        : machine_(m),
          options_(o),
          dialect_(dialect),
          layout_(AxisLayout::fromMachine(m)),
          interp_(layout_, InterpreterOptions{dialect, o.setup, o.rotaryShortest}),
          corrector_(m, d, o.corrector),
          summary_(s),
          out_(out) {
        outPos_ = AxisVector::Zero(layout_.count);
        lastDelta_ = AxisVector::Zero(layout_.count);
        qEnd_ = AxisVector::Zero(layout_.count);
        pieces_.reserve(static_cast<size_t>(o.corrector.maxPieces) + 4);
        all_ = layout_.all();
    }

    void line(const Line& ln);

private:
    void notice(bool warning, uint64_t line, std::string message);
    void overlong(uint64_t no);
    void updateStyles(const LexedBlock& b);
    void warnings(uint64_t no);
    void passThrough(const Line& ln, uint64_t no);
    void move(const Line& ln, uint64_t no);
    void updateOutputAfterPassThrough();
    // Text helpers.
    int decimalsFor(char letter, bool rotary) const;
    NumberStyle styleFor(char letter, bool rotary, const Word* original, bool& increments) const;
    size_t number(char letter, bool rotary, double programValue, const Word* original, char* out, double& readBack,
                  double& resolution) const;
    size_t motionText(Motion m, char* out) const;
    char sep() const { return b_.spaced ? ' ' : '\0'; }
    char letterCase(char c) const { return b_.lowerCase ? static_cast<char>(c | 0x20) : c; }
    /// Word needed for axis a to reach q (machine)? Writes "A1.234" into text (len) and updates the output
    /// position. `existing` is the word index in the block (piece 1) or -1.
    bool axisWord(int a, double q, int existing, char* text, size_t& len, bool& replace);
    bool insertMotionWord(Motion m);
    size_t arcWords(const ArcFit& fit, const AxisVector& outStart, uint32_t insertPos);

    const MachineModel& machine_;
    const CorrectOptions& options_;
    Dialect dialect_;
    AxisLayout layout_;
    Interpreter interp_;
    Corrector corrector_;
    CorrectSummary& summary_;
    OutputBuffer& out_;
    LexedBlock b_;
    BlockResult r_;
    BlockEdits edits_;
    std::array<LetterStyle, 26> styles_{};
    bool gPadded_ = false;
    bool fixedProgram_ = false;  ///< some dimension word keeps trailing zeros: write fixed decimals everywhere
    AxisVector outPos_, lastDelta_, qEnd_;
    AxisMask outKnown_ = 0, all_ = 0;
    Motion outMotion_ = Motion::Unknown;
    std::vector<Piece> pieces_;
    OverlongLine long_;
    bool warnedCr_ = false;
    bool warnedDecimals_ = false;
    std::string lastEol_ = "\n";
};

void ProgramCorrector::notice(bool warning, uint64_t line, std::string message) {
    auto& list = warning ? summary_.warnings : summary_.passThrough;
    if (warning) ++summary_.warningCount;
    if (options_.report) {
        // Plain CSV without quoting (as every CSV of the project): commas in messages become semicolons.
        std::string m = message;
        std::replace(m.begin(), m.end(), ',', ';');
        *options_.report << line << ',' << (warning ? "warning" : "pass-through") << ',' << m << '\n';
    }
    if (list.size() < CorrectSummary::kMaxNotices) list.push_back({line, std::move(message)});
}

void ProgramCorrector::updateStyles(const LexedBlock& b) {
    for (int i = 0; i < b.count; ++i) {
        const Word& w = b.words[i];
        if (w.kind != ValueKind::Number) continue;
        LetterStyle& s = styles_[w.letter - 'A'];
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
}

void ProgramCorrector::warnings(uint64_t no) {
    for (int k = 0; k < r_.warningCount; ++k) {
        const auto [w, code] = r_.warnings[k];
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
    const int floor = rotary ? 4 : (r_.inch ? 5 : 4);
    return std::max(styles_[letter - 'A'].maxDecimals, floor);
}

NumberStyle ProgramCorrector::styleFor(char letter, bool rotary, const Word* original, bool& increments) const {
    const LetterStyle& ls = styles_[letter - 'A'];
    NumberStyle st;
    increments = r_.integerIncrements && letter != 'F' &&
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
        const double counts = std::round(pv / r_.increment);
        readBack = counts * r_.increment;
        resolution = r_.increment;
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
    const bool wrap = (r_.wrap & bit) != 0;
    const bool absolute = r_.absolute || r_.machineCoordinates;
    const double scale = r_.scale[a], off = r_.offset[a];
    const Word* orig = existing >= 0 ? &b_.words[existing] : nullptr;
    const double origPv = orig ? interp_.wordValue(*orig) : 0.0;
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
        if (sep() && len == 0) text[len++] = ' ';
        text[len++] = letterCase(layout_.letter[a]);
        std::memcpy(text + len, num, n);
        len += n;
    }
    return true;
}

bool ProgramCorrector::insertMotionWord(Motion m) {
    char t[16];
    size_t n = 0;
    const bool lead = b_.count > 0 && b_.words[0].letter == 'N';
    uint32_t pos = lead ? b_.words[0].end : (b_.count > 0 ? b_.words[0].begin : b_.codeEnd);
    if (lead && sep()) t[n++] = ' ';
    n += motionText(m, t + n);
    if (!lead && sep()) t[n++] = ' ';
    return edits_.add(pos, pos, std::string_view(t, n));
}

void ProgramCorrector::updateOutputAfterPassThrough() {
    for (int a = 0; a < layout_.count; ++a) {
        const AxisMask bit = 1u << a;
        if (!(r_.endKnown & bit)) {
            outKnown_ &= ~bit;
            continue;
        }
        if (!(r_.words & bit)) continue;
        if (r_.absolute || r_.machineCoordinates) {
            outPos_[a] = r_.end[a];
            outKnown_ |= bit;
        } else if ((outKnown_ & bit) && (r_.startKnown & bit)) {
            outPos_[a] += r_.end[a] - r_.start[a];
        } else {
            outKnown_ &= ~bit;
        }
    }
}

void ProgramCorrector::passThrough(const Line& ln, uint64_t no) {
    ++summary_.passedThrough;
    if (!r_.report) ++summary_.notCorrected;
    edits_.clear();
    // After an arc was turned into lines, the output's modal motion differs: restore it where this block relies on it.
    const bool relies = r_.words != 0 && !r_.motionCode;
    const bool motionKnown = r_.motion == Motion::Rapid || r_.motion == Motion::Linear || r_.motion == Motion::ArcCw ||
                             r_.motion == Motion::ArcCcw;
    bool restored = false;
    if (relies && motionKnown && outMotion_ != r_.motion && !edits_.overflow()) restored = insertMotionWord(r_.motion);
    if (r_.report) {
        std::string detail;
        if (r_.reasonLetter) detail = fmt::format(" (axis {})", r_.reasonLetter);
        else if (r_.reasonCode)
            detail = r_.reasonCode % 10 ? fmt::format(" (G{}.{})", r_.reasonCode / 10, r_.reasonCode % 10)
                                        : fmt::format(" (G{})", r_.reasonCode / 10);
        notice(false, no, fmt::format("{}{}{}", r_.reason ? r_.reason : "not evaluated", detail,
                                      restored ? "; motion word inserted to keep the modal motion" : ""));
    }
    if (restored) {
        edits_.apply(ln.text, out_);
        ++summary_.corrected;
    } else {
        out_.write(ln.text);
    }
    out_.write(ln.eol);
    if (r_.motionCode) outMotion_ = r_.motion;
    if (restored) outMotion_ = r_.motion;
    updateOutputAfterPassThrough();
}

size_t ProgramCorrector::arcWords(const ArcFit& fit, const AxisVector& outStart, uint32_t insertPos) {
    // Centre words of the plane: (I,J) G17, (K,I) G18, (J,K) G19, or R.
    const int a0 = r_.arc.axis0, a1 = r_.arc.axis1;
    const char l0 = layout_.letter[a0] == 'X' ? 'I' : layout_.letter[a0] == 'Y' ? 'J' : 'K';
    const char l1 = layout_.letter[a1] == 'X' ? 'I' : layout_.letter[a1] == 'Y' ? 'J' : 'K';
    size_t changes = 0;
    char num[kMaxNumberChars];
    double readBack, res;
    if (r_.arc.radiusForm) {
        const Word* R = b_.find('R');
        const double radius = std::hypot(outStart[a0] - fit.c0, outStart[a1] - fit.c1) / r_.scale[a0];
        const double origPv = interp_.wordValue(*R);
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
        const double pv = r_.arcAbsolute ? (c[k] - r_.offset[a]) / r_.scale[a] : (c[k] - outStart[a]) / r_.scale[a];
        const Word* w = b_.find(let[k]);
        const double origPv = w ? interp_.wordValue(*w) : 0.0;
        const size_t n = number(let[k], false, pv, w, num, readBack, res);
        if (std::fabs(pv - origPv) < 0.5 * res) continue;
        ++changes;
        if (w) {
            edits_.add(w->valueBegin, w->end, std::string_view(num, n));
        } else {
            char t[kMaxNumberChars + 4];
            size_t len = 0;
            if (sep()) t[len++] = ' ';
            t[len++] = letterCase(let[k]);
            std::memcpy(t + len, num, n);
            len += n;
            edits_.add(insertPos, insertPos, std::string_view(t, len));
        }
    }
    return changes;
}

void ProgramCorrector::move(const Line& ln, uint64_t no) {
    ++summary_.moves;
    const int n = layout_.count;
    const double L = r_.tipLength;
    const bool identity = corrector_.identity();
    const bool isArc = r_.motion == Motion::ArcCw || r_.motion == Motion::ArcCcw;
    const bool isRapid = r_.motion == Motion::Rapid && !r_.rapidIsFeed;
    const bool outStartKnown = (outKnown_ & all_) == all_;
    const bool nomStartKnown = (r_.startKnown & all_) == all_;

    // Corrected end point.
    if (identity) {
        qEnd_ = r_.end;
    } else {
        const SolveResult s = corrector_.solve(r_.end, L, r_.end + lastDelta_, qEnd_);
        summary_.maxTipResidual = std::max(summary_.maxTipResidual, s.tipError);
        summary_.maxAxisResidual = std::max(summary_.maxAxisResidual, s.axisError);
        if (!s.converged || !(s.tipError < 1e-5)) {
            ++summary_.unconverged;
            notice(true, no, fmt::format("the correction did not converge (tip residual {:.3g} um); end point left uncorrected",
                                         s.tipError / kUm));
            qEnd_ = r_.end;
        } else {
            lastDelta_ = qEnd_ - r_.end;
        }
        for (int a = 0; a < n; ++a) {
            const double d = std::fabs(qEnd_[a] - r_.end[a]);
            if (layout_.rotary[a]) {
                if (d > summary_.maxRotaryCorrection) summary_.maxRotaryCorrection = d, summary_.maxRotaryLine = no;
            } else if (d > summary_.maxLinearCorrection) {
                summary_.maxLinearCorrection = d, summary_.maxLinearLine = no;
            }
            const Link& link = machine_.axisLink(a);
            if ((qEnd_[a] < link.min - 1e-9 || qEnd_[a] > link.max + 1e-9) && r_.end[a] >= link.min && r_.end[a] <= link.max)
                notice(true, no, fmt::format("corrected axis {} command is outside its travel", layout_.letter[a]));
        }
    }

    // Pieces.
    pieces_.clear();
    SplitStats stats;
    bool arcKept = false, arcToLines = false;
    ArcFit fit;
    const AxisVector outStart = outPos_;
    if (isArc) {
        if (!outStartKnown) {
            r_.reason = "arc from an output position that is not known";
            r_.report = true;
            passThrough(ln, no);
            return;
        }
        const MovePath path = MovePath::arc(r_.start, r_.end, r_.arc);
        const bool closed = std::hypot(r_.end[r_.arc.axis0] - r_.start[r_.arc.axis0],
                                       r_.end[r_.arc.axis1] - r_.start[r_.arc.axis1]) < 1e-12;
        if (closed && !identity) {
            // A full circle must end exactly where the controller starts it, digit for digit.
            qEnd_[r_.arc.axis0] = outStart[r_.arc.axis0];
            qEnd_[r_.arc.axis1] = outStart[r_.arc.axis1];
        }
        fit = corrector_.fitArc(path, outStart, qEnd_, L, closed);
        if (fit.ok || r_.stop) {
            if (!fit.ok)
                notice(true, no, fmt::format("arc kept although {:.3f} um off the nominal path: the block holds a program stop",
                                             fit.maxDeviation / kUm));
            arcKept = true;
            summary_.maxPathDeviation = std::max(summary_.maxPathDeviation, fit.maxDeviation);
            pieces_.push_back({1.0, qEnd_});
        } else {
            corrector_.splitArc(path, outStart, qEnd_, L, pieces_, stats);
            arcToLines = true;
            ++summary_.arcsToLines;
        }
    } else {
        const MovePath path = MovePath::line(r_.start, r_.end);
        const bool measurable = nomStartKnown && outStartKnown && !identity;
        const bool subdivide = measurable && !isRapid && !r_.stop;
        if (measurable && !isRapid) corrector_.split(path, outStart, qEnd_, L, subdivide, pieces_, stats);
        else pieces_.push_back({1.0, qEnd_});
    }
    summary_.maxPathDeviation = std::max(summary_.maxPathDeviation, stats.maxDeviation);
    if (stats.limited) notice(true, no, fmt::format("tolerance not met after the subdivision limit ({:.3f} um left)", stats.maxDeviation / kUm));
    const bool inverseTime = r_.feedMode == FeedMode::InverseTime;
    if (pieces_.size() > 1 && inverseTime && r_.feedWord < 0)
        notice(true, no, "inverse-time move without F split: the pieces carry no feed");

    // Piece 1 goes onto the original block.
    edits_.clear();
    const Motion pieceMotion = arcToLines ? Motion::Linear : r_.motion;
    if (r_.motionWord >= 0) {
        if (arcToLines) {
            const Word& g = b_.words[r_.motionWord];
            char t[4];
            size_t k = 0;
            if (g.digitsBefore >= 2) t[k++] = '0';
            t[k++] = '1';
            edits_.add(g.valueBegin, g.end, std::string_view(t, k));
        }
    } else if (outMotion_ != pieceMotion) {
        insertMotionWord(pieceMotion);
    }
    // Where new words go: after the last axis / centre word, else after the motion word, else at the end of the code.
    uint32_t insertPos = 0;
    bool anchor = false;
    for (int i = 0; i < b_.count; ++i) {
        const char c = b_.words[i].letter;
        if (layout_.axis(c) >= 0 || c == 'I' || c == 'J' || c == 'K' || c == 'R') {
            insertPos = std::max(insertPos, b_.words[i].end);
            anchor = true;
        }
    }
    if (!anchor) insertPos = r_.motionWord >= 0 ? b_.words[r_.motionWord].end : b_.codeEnd;
    char text[BlockEdits::kArena / 4];
    size_t textLen = 0;
    static constexpr char kOrder[] = "XYZUVWABC";
    auto axesOf = [&](const AxisVector& q, bool onBlock, char* buf, size_t& used) {
        // Existing words in place; missing ones appended in X Y Z U V W A B C order.
        for (const char* p = kOrder; *p; ++p) {
            const int a = layout_.axis(*p);
            if (a < 0) continue;
            const int existing = onBlock ? r_.axisWord[a] : -1;
            char w[kMaxNumberChars + 4];
            size_t len = 0;
            bool replace = false;
            if (!axisWord(a, q[a], existing, w, len, replace)) continue;
            if (replace && existing >= 0 && existing < b_.count) {
                const Word& word = b_.words[static_cast<size_t>(existing)];
                edits_.add(word.valueBegin, word.end, std::string_view(w, len));
            } else {
                std::memcpy(buf + used, w, len);
                used += len;
            }
        }
        for (int a = 0; a < n; ++a) {
            // Axes with letters outside the usual set.
            if (std::strchr(kOrder, layout_.letter[a])) continue;
            const int existing = onBlock ? r_.axisWord[a] : -1;
            char w[kMaxNumberChars + 4];
            size_t len = 0;
            bool replace = false;
            if (!axisWord(a, q[a], existing, w, len, replace)) continue;
            if (replace && existing >= 0 && existing < b_.count) {
                const Word& word = b_.words[static_cast<size_t>(existing)];
                edits_.add(word.valueBegin, word.end, std::string_view(w, len));
            } else {
                std::memcpy(buf + used, w, len);
                used += len;
            }
        }
    };
    axesOf(pieces_[0].q, true, text, textLen);
    if (arcKept && !identity) arcWords(fit, outStart, insertPos);
    if (arcToLines) {
        for (int i = 0; i < b_.count; ++i) {
            const Word& w = b_.words[i];
            const bool centre = w.letter == 'I' || w.letter == 'J' || w.letter == 'K' || w.letter == 'R' ||
                                (w.letter == 'P' && dialect_ == Dialect::Rs274ngc);
            if (!centre) continue;
            uint32_t begin = w.begin;
            if (begin > 0 && (ln.text[begin - 1] == ' ' || ln.text[begin - 1] == '\t')) --begin;
            edits_.add(begin, w.end, {});
        }
    }
    char num[kMaxNumberChars];
    double readBack, res;
    auto feedOf = [&](size_t k) {
        const double dt = pieces_[k].t - (k == 0 ? 0.0 : pieces_[k - 1].t);
        return r_.feed / std::max(dt, 1e-12);
    };
    if (inverseTime && pieces_.size() > 1 && r_.feedWord >= 0) {
        const Word& f = b_.words[r_.feedWord];
        const size_t k = number('F', false, feedOf(0), &f, num, readBack, res);
        edits_.add(f.valueBegin, f.end, std::string_view(num, k));
    }
    if (textLen > 0) edits_.add(insertPos, insertPos, std::string_view(text, textLen));
    if (edits_.overflow()) {
        r_.reason = "block too long to rewrite";
        r_.report = true;
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

    // Further pieces: new lines after the block.
    if (pieces_.size() > 1) {
        ++summary_.split;
        summary_.addedLines += pieces_.size() - 1;
        // Indentation and block delete of the original line.
        size_t indent = 0;
        while (indent < ln.text.size() && (ln.text[indent] == ' ' || ln.text[indent] == '\t')) ++indent;
        std::string_view prefix = ln.text.substr(0, indent);
        std::string_view skip;
        if (b_.blockDelete >= 0) {
            size_t e = static_cast<size_t>(b_.blockDelete) + 1;
            while (e < ln.text.size() && std::isdigit(static_cast<unsigned char>(ln.text[e]))) ++e;
            skip = ln.text.substr(static_cast<size_t>(b_.blockDelete), e - static_cast<size_t>(b_.blockDelete));
        }
        const Motion lineMotion = r_.motion == Motion::Rapid ? Motion::Rapid : Motion::Linear;
        for (size_t k = 1; k < pieces_.size(); ++k) {
            out_.write(ln.eol.empty() ? std::string_view(lastEol_) : ln.eol);
            char buf[1024];
            size_t used = 0;
            used += motionText(lineMotion, buf);
            axesOf(pieces_[k].q, false, buf, used);
            if (inverseTime && r_.feedWord >= 0) {
                if (sep()) buf[used++] = ' ';
                buf[used++] = letterCase('F');
                used += number('F', false, feedOf(k), &b_.words[r_.feedWord], buf + used, readBack, res);
            }
            out_.write(prefix);
            out_.write(skip);
            out_.write(std::string_view(buf, used));
        }
    }
    out_.write(ln.eol);
    outMotion_ = arcToLines ? Motion::Linear : r_.motion;
}

void ProgramCorrector::overlong(uint64_t no) {
    if (!long_.code) return;  // white space and comments only: nothing it could change
    ++summary_.blocks;
    ++summary_.passedThrough;
    const bool modal = interp_.forgetOverlong(long_, r_);
    std::string axes;
    for (int a = 0; a < layout_.count; ++a)
        if (r_.words & (1u << a)) axes.push_back(layout_.letter[a]);
    if (modal) {
        outKnown_ = 0;
        outMotion_ = Motion::Unknown;
    } else {
        outKnown_ &= ~r_.words;
    }
    notice(false, no,
           fmt::format("line longer than {} bytes: passed through unparsed; {}", options_.bufferSize,
                       modal ? "it holds codes that may change any mode: every position is unknown afterwards"
                             : axes.empty() ? "it names no axis: positions kept"
                                            : fmt::format("positions of {} unknown afterwards", axes)));
}

void ProgramCorrector::line(const Line& ln) {
    const uint64_t no = ln.number;
    if (ln.firstPiece) ++summary_.lines;  // the pieces of an overlong line count as one line
    if (ln.eol.size() == 1 && ln.eol[0] == '\r' && !warnedCr_) {
        warnedCr_ = true;
        notice(true, no, "lines end with a lone CR (classic Mac OS line ends): read as line ends and kept");
    }
    if (ln.partial) {
        out_.write(ln.text);
        out_.write(ln.eol);
        if (ln.firstPiece) long_.reset();
        long_.feed(ln.text);
        if (ln.lastPiece) overlong(no);
        return;
    }
    lexBlock(ln.text, dialect_, b_, no == 1);
    updateStyles(b_);
    interp_.interpret(ln.text, b_, r_);
    warnings(no);
    // Axes taken at 0 until commanded are at 0 for the output controller too.
    if (const AxisMask fresh = interp_.assumed() & ~outKnown_) {
        for (int a = 0; a < layout_.count; ++a)
            if (fresh & (1u << a)) outPos_[a] = r_.start[a];
        outKnown_ |= fresh;
    }
    switch (r_.kind) {
        case BlockKind::Empty:
            out_.write(ln.text);
            out_.write(ln.eol);
            return;
        case BlockKind::NoMotion:
            ++summary_.blocks;
            out_.write(ln.text);
            out_.write(ln.eol);
            if (r_.motionCode) outMotion_ = r_.motion;
            return;
        case BlockKind::PassThrough:
            ++summary_.blocks;
            passThrough(ln, no);
            return;
        case BlockKind::Move:
            ++summary_.blocks;
            move(ln, no);
            return;
    }
}

}  // namespace

CorrectSummary correctProgram(const MachineModel& machine, const DeviationSet& deviations, std::istream& in,
                              std::ostream& out, const CorrectOptions& options) {
    CorrectSummary s;
    LineReader reader(in, options.bufferSize);
    const std::string_view head = reader.head();
    checkTextHead(head, options.inputName);
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
    ProgramCorrector pc(machine, deviations, options, s.dialect, s, buffer);
    Line line;
    while (reader.next(line)) {
        pc.line(line);
        if (options.progress && (line.number & 0x1fff) == 0 && line.lastPiece) options.progress(reader.bytesConsumed());
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
    if (s.unconverged) t += fmt::format("endpoints not converged (left unchanged): {}\n", s.unconverged);
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
