#pragma once
// Streaming line reader over a fixed buffer: constant memory whatever the file size. Lines are views into
// the buffer, valid until the next call. A line longer than the buffer comes in pieces (partial = true),
// which the caller passes through unparsed.
#include <cstdint>
#include <istream>
#include <string_view>
#include <vector>

namespace cnccomp::pp {

struct Line {
    std::string_view text;  ///< the block without its line ending
    std::string_view eol;   ///< "\n", "\r\n" or "" (last line without ending, or a piece of an overlong line)
    bool partial = false;   ///< a piece of a line longer than the buffer (more pieces follow or preceded)
};

class LineReader {
public:
    explicit LineReader(std::istream& in, size_t capacity = size_t{1} << 20);
    /// The first bytes of the stream (up to the buffer size) without consuming them (for dialect detection).
    std::string_view head();
    /// Next line; false at the end of the stream. Throws std::runtime_error on a read error.
    bool next(Line& line);
    uint64_t bytesConsumed() const { return consumed_; }

private:
    void fill();
    std::istream& in_;
    std::vector<char> buf_;
    size_t begin_ = 0, end_ = 0;
    bool eof_ = false;
    bool inLongLine_ = false;
    uint64_t consumed_ = 0;
};

}  // namespace cnccomp::pp
