#pragma once
// Writing blocks: an output buffer over a stream, and the edits of one block (replace a byte span,
// insert text) applied to the original line so that every byte outside the edits is kept.
#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <memory>
#include <ostream>
#include <string_view>
#include <vector>

namespace cnccomp::postproc {

/// n bytes (sizeof(Word) ≤ n ≤ 2 sizeof(Word)) from s to d as two overlapping Word moves: the first and the last Word.
template <class Word>
inline void copyTwoWords(char* d, const char* s, size_t n) {
    Word a, b;
    std::memcpy(&a, s, sizeof a);
    std::memcpy(&b, s + n - sizeof b, sizeof b);
    std::memcpy(d, &a, sizeof a);
    std::memcpy(d + n - sizeof b, &b, sizeof b);
}

/// Copies n bytes to d and returns d + n: words and the spans between them are a few bytes, for which a call to
/// memmove costs more than the copy (two overlapping fixed-size moves up to 16 bytes).
inline char* copyBytes(char* d, const char* s, size_t n) {
    if (n > 16) {
        std::memcpy(d, s, n);
    } else if (n >= 8) {
        copyTwoWords<uint64_t>(d, s, n);
    } else if (n >= 4) {
        copyTwoWords<uint32_t>(d, s, n);
    } else if (n > 0) {
        const char a = s[0], b = s[n / 2], c = s[n - 1];
        d[0] = a;
        d[n / 2] = b;
        d[n - 1] = c;
    }
    return d + n;
}

/// Buffered writes to a stream: at most `capacity` bytes are held before they are written. The storage is not
/// allocated at full capacity up front: it starts at 4 KiB and doubles as the output grows (never zero-filled), so a
/// short output (a few blocks, a fuzz input) costs a small allocation, not a 1 MiB zero-filled one (measured under
/// AddressSanitizer: the zero fill of 1 MiB per call was 80 % of the Klartext reader's fuzz target, ~330 page faults
/// an input). The bytes reach the stream in the same order whatever the storage size.
class OutputBuffer {
public:
    explicit OutputBuffer(std::ostream& out, size_t capacity = size_t{1} << 20);
    ~OutputBuffer();
    OutputBuffer(const OutputBuffer&) = delete;
    OutputBuffer& operator=(const OutputBuffer&) = delete;
    void write(std::string_view s) {
        if (s.size() > size_ - used_ && !makeRoom(s.size())) {
            out_.write(s.data(), static_cast<std::streamsize>(s.size()));
            written_ += s.size();
            return;
        }
        std::copy(s.begin(), s.end(), buf_.get() + used_);
        used_ += s.size();
    }
    /// Room for `n` more bytes (the storage grown or flushed), nullptr when n exceeds the capacity; the caller writes at
    /// most n bytes there and commits the count it wrote.
    char* reserve(size_t n) {
        if (n > size_ - used_ && !makeRoom(n)) return nullptr;
        return buf_.get() + used_;
    }
    void commit(size_t n) { used_ += n; }
    void flush();
    uint64_t bytesWritten() const { return written_ + used_; }

private:
    /// Grows the storage (up to the capacity) or flushes so that `need` more bytes fit; false when `need` exceeds the
    /// capacity (the buffer is flushed and the caller writes the bytes directly).
    bool makeRoom(size_t need);
    void resize(size_t size);
    std::ostream& out_;
    size_t capacity_;
    std::unique_ptr<char[]> buf_;
    size_t size_ = 0;  ///< allocated bytes of buf_ (<= capacity_)
    size_t used_ = 0;
    uint64_t written_ = 0;
};

/// Edits of one block: replacements of byte spans of the original line and insertions (begin == end).
/// Replacement text lives in a fixed arena; no allocation per block.
class BlockEdits {
public:
    static constexpr int kMaxEdits = 96;
    static constexpr size_t kArena = 16384;

    void clear() {
        count_ = 0;
        used_ = 0;
        overflow_ = false;
        sorted_ = true;
        maxEnd_ = 0;
    }
    /// Replace [begin, end) by `text` (insert when begin == end). Returns false when full (the caller then
    /// writes the block unchanged and reports it).
    bool add(uint32_t begin, uint32_t end, std::string_view text);
    /// A writable tail of the arena for composing text; commit with add(begin, end, view) on the returned span.
    char* scratch(size_t need);
    bool empty() const { return count_ == 0; }
    bool overflow() const { return overflow_; }
    /// Original line with the edits applied (edits sorted by position; insertions keep their order).
    void apply(std::string_view line, OutputBuffer& out);

private:
    struct Edit {
        uint32_t begin, end, textBegin, textLen, order;
    };
    /// The order apply() writes the edits in: by position; at one position insertions (empty spans) before
    /// replacements; else as added.
    static bool before(const Edit& a, const Edit& b) {
        if (a.begin != b.begin) return a.begin < b.begin;
        const bool ai = a.begin == a.end, bi = b.begin == b.end;
        if (ai != bi) return ai;
        return a.order < b.order;
    }
    std::array<Edit, kMaxEdits> edits_{};
    std::array<char, kArena> arena_{};
    int count_ = 0;
    size_t used_ = 0;
    bool overflow_ = false;
    bool sorted_ = true;   ///< added in apply()'s order so far (usually: the words, then what follows them)
    uint32_t maxEnd_ = 0;  ///< the largest span end added (all edits within a line at least that long)
};

}  // namespace cnccomp::postproc
