// The back end's text: the style of the program's words (decimals, trailing zeros, spacing, alignment) and the words it
// writes or replaces in that style.
#include "postproc/correct_back_end.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>

#include <fmt/format.h>

namespace cnccomp::postproc::iso {
using namespace cnccomp::io;

namespace {

double circular(double d) { return d - 360.0 * std::round(d / 360.0); }

}  // namespace

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
    copyBytes(out + len, num, n);
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
        copyBytes(text, num, n);
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

}  // namespace cnccomp::postproc::iso
