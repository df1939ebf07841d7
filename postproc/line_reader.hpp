#pragma once
// Streaming line reader over a fixed buffer: constant memory whatever the file size. Lines are views into
// the buffer, valid until the next call. Line endings are "\n", "\r\n" and a lone "\r" (classic Mac OS files).
// A line longer than the buffer comes in pieces (partial = true) that share one line number; the caller passes
// them through unparsed (see OverlongLine in lexer.hpp for what such a line may change).
#include <cstdint>
#include <istream>
#include <string_view>
#include <vector>

namespace cnccomp::postproc {

struct Line {
    std::string_view text;  ///< the block without its line ending
    std::string_view eol;   ///< "\n", "\r\n", "\r" or "" (last line without ending, or a piece of an overlong line)
    uint64_t number = 0;    ///< 1-based line number; every piece of an overlong line has the line's number
    bool partial = false;   ///< a piece of a line longer than the buffer (more pieces follow or preceded)
    bool firstPiece = true; ///< the first piece of its line (always true for a whole line)
    bool lastPiece = true;  ///< the last piece of its line (always true for a whole line)
};

class LineReader {
public:
    explicit LineReader(std::istream& in, size_t capacity = size_t{1} << 20);
    /// The first bytes of the stream (up to the buffer size) without consuming them (for dialect detection).
    std::string_view head();
    /// Next line; false at the end of the stream. Throws std::runtime_error on a read error.
    bool next(Line& line);
    uint64_t bytesConsumed() const { return consumed_; }
    /// Lines that ended with a lone '\r'.
    uint64_t crOnlyEndings() const { return crOnly_; }

private:
    void fill();
    /// Index of the first '\n' or '\r' at or after begin_, or end_ when there is none in the buffer.
    size_t findEnd();
    std::istream& in_;
    std::vector<char> buf_;
    size_t begin_ = 0, end_ = 0;
    size_t nl_ = 0, cr_ = 0;  ///< cached positions of the next '\n' / '\r' (end_ when none), valid when >= begin_
    bool cacheValid_ = false;
    bool eof_ = false;
    bool inLongLine_ = false;
    uint64_t consumed_ = 0;
    uint64_t lineNo_ = 0;
    uint64_t crOnly_ = 0;
};

}  // namespace cnccomp::postproc
