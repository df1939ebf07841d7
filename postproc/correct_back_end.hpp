#pragma once
// The back end of the RS274NGC-family corrector: checks and splits the path between corrected end points and writes
// every line, changed words in the program's own style (postproc/correct_block_text.cpp), every other byte as read.
#include <algorithm>
#include <array>
#include <string>
#include <string_view>
#include <vector>

#include "cnccomp/deviations.hpp"
#include "cnccomp/io/number_format.hpp"
#include "postproc/block_writer.hpp"
#include "postproc/correct_program.hpp"
#include "postproc/correct_record.hpp"
#include "postproc/line_reader.hpp"

namespace cnccomp::postproc::iso {

struct LetterStyle {
    int maxDecimals = -1;
    bool trailingZero = false, bare = false, sawPoint = false, sawInteger = false;
};

/// How the words of one block are spaced and aligned, so that words added to it (or lines added after it) look like
/// its own: the white space between words, between a letter and its number, and whether positive numbers take the
/// place of a minus sign ("X  16.339  Y -25.409").
struct BlockStyle {
    std::array<char, 8> sep{};
    size_t sepLen = 0;
    int valueGap = 0;      ///< spaces between the letter and the number of the block's last axis word
    bool anchorNeg = false;
};

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
    // Called once per line or move, in the file that defines them: inline, so that they are inlined there.
    inline void warnings(uint64_t no);
    void passThrough(const Line& ln, uint64_t no);
    /// What the path check decided for one move: its pieces are pieces_.
    struct MovePieces {
        bool outStartKnown = false;
        bool arcKept = false, arcToLines = false;
        ArcFit fit;
        AxisVector outStart;  ///< the output's position at the start of the move
        bool endBounded = false;  ///< a corrected straight TCP-angles move: the next may bound its midpoint from here
        double endBound = 0;      ///< mm: MidpointBound::endBound of this move's end
    };
    /// The last move's end as the midpoint bound of the next move needs it (postproc/midpoint_bound.hpp): valid after a
    /// corrected straight TCP-angles move written as corrected, until any block other than a move or an empty one.
    struct BoundedEnd {
        bool valid = false;
        MoveSpace space;
        AxisVector corrected, nominal;  ///< program space: the unrounded corrected end, the nominal end
        double bound = 0;               ///< mm: MidpointBound::endBound
    };
    /// The midpoint bound of the current straight move (HUGE_VAL where the bound does not apply).
    double currentMidpointBound(const Record& rec, const PathContext& ctx, const ProgramPoint& qEnd,
                                double endBound) const;
    /// A move: the summary's counts, then its pieces (findPieces), then its words (writeMove).
    void move(Record& rec);
    /// The pieces of the move ending at the corrected program position `qEnd`: the arc kept (refitted), the arc as
    /// lines, or the line split where the tolerance needs it. False: an arc from an unknown output position.
    bool findPieces(const Record& rec, ProgramPoint qEnd, MovePieces& p);
    /// Piece 1 onto the block's own words, the further pieces as new lines in the block's style.
    void writeMove(const Record& rec, const Line& ln, const MovePieces& p);
    void switchMode();
    void updateOutputAfterPassThrough();
    inline double toleranceFor(const MoveSpace& space, uint64_t no);
    // Text helpers.
    // Called for every number written: defined below, in the header, so that they are inlined.
    int decimalsFor(char letter, bool rotary) const;
    io::NumberStyle styleFor(char letter, bool rotary, const Word* original, bool& increments) const;
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
    BoundedEnd lastEnd_;
    Motion outMotion_ = Motion::Unknown;
    std::vector<Piece> pieces_;
    int linearCount_ = 0, rotaryCount_ = 0;
    bool warnedCr_ = false, warnedTolerance_ = false;
    std::string lastEol_ = "\n";
};

inline int ProgramCorrector::decimalsFor(char letter, bool rotary) const {
    if (options_.decimals >= 0) return options_.decimals;
    const int floor = rotary ? 4 : (r_->inch ? 5 : 4);
    return std::max(styles_[letter - 'A'].maxDecimals, floor);
}

inline io::NumberStyle ProgramCorrector::styleFor(char letter, bool rotary, const Word* original, bool& increments) const {
    const LetterStyle& ls = styles_[letter - 'A'];
    io::NumberStyle st;
    increments = r_->integerIncrements && letter != 'F' &&
                 ((original && !original->point) || (!original && ls.sawInteger && !ls.sawPoint));
    st.point = !increments;
    st.decimals = decimalsFor(letter, rotary);
    st.fixed = ls.trailingZero || fixedProgram_;
    st.bareFraction = ls.bare;
    st.plus = original && original->plus;
    return st;
}

}  // namespace cnccomp::postproc::iso
