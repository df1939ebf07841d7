#pragma once
// The interpreter's first step: read one lexed block into what it says, without changing any state (LinuxCNC
// src/emc/rs274ngc/interp_read.cc: read_items fills a `block` struct that interp_check.cc and interp_convert.cc then
// use). Here the block is lexed already (postproc/lexer.hpp); this step sorts its words: G codes (as G × 10), axis
// words per machine axis, the M codes that stop, call or switch tool-tip programming, the F H T P L O words, arc
// words, and the Sinumerik keywords (TRAORI, SUPA, DIAMON …).
#include <array>
#include <cstdint>
#include <string_view>

#include "postproc/lexer.hpp"
#include "postproc/modal.hpp"

namespace cnccomp::postproc {

/// What one block says, as read (no modal state applied). Pointers point into the LexedBlock.
struct BlockWords {
    uint32_t flags = 0;  ///< the lexer's flags, kIdentifier / kCall cleared when every keyword was understood
    // Keywords (multi-letter words).
    bool flow = false;            ///< a control-flow keyword (IF, GOTO, WHILE …)
    bool unknownKeyword = false;  ///< a keyword or call this interpreter does not know
    bool tcpOn = false, tcpOff = false, transformOn = false, machineKeyword = false;
    int diameterKeyword = -1;     ///< DIAMON 1, DIAMOF 0, none -1
    // G words: code × 10 and the word index, in block order.
    std::array<int, 16> gCode{}, gWord{};
    int nG = 0;
    bool gProblem = false;        ///< a G word that is not a plain G code (or more than 16)
    // M words.
    bool mCall = false, mSubEnd = false, userTcpOn = false, userTcpOff = false;
    // Other words.
    bool duplicateAxis = false;
    char foreignAxis = 0;         ///< first axis letter the machine does not have, 0 none
    const Word *F = nullptr, *H = nullptr, *T = nullptr, *P = nullptr, *L = nullptr, *O = nullptr;
    bool arcWords = false;        ///< I, J, K or R
    bool extProblem = false;      ///< an extended address other than A3= B3= C3=
    std::array<int, 3> ijk{{-1, -1, -1}};  ///< word index of I J K, -1 none
};

/// Reads the block's keywords and words into `w`; fills the block's word fields of `r` (axisWord, words, vectorWord,
/// feedWord, stop). `line` is the text the block was lexed from.
void readBlockWords(std::string_view line, const LexedBlock& b, const AxisLayout& layout,
                    const InterpreterOptions& options, BlockWords& w, BlockResult& r);

}  // namespace cnccomp::postproc
