#include "postproc/block_writer.hpp"

#include <algorithm>
#include <cstring>

namespace cnccomp::postproc {

OutputBuffer::OutputBuffer(std::ostream& out, size_t capacity) : out_(out), capacity_(std::max<size_t>(capacity, 64)) {
    resize(std::min<size_t>(capacity_, 4096));
}

OutputBuffer::~OutputBuffer() {
    // flush() is explicit: a destructor must not throw, and a failed run must not look complete.
}

void OutputBuffer::resize(size_t size) {
    std::unique_ptr<char[]> grown(new char[size]);  // default-initialised: no zero fill
    if (used_) std::memcpy(grown.get(), buf_.get(), used_);
    buf_ = std::move(grown);
    size_ = size;
}

bool OutputBuffer::makeRoom(size_t need) {
    if (need <= capacity_ - used_) {  // fits once the storage has grown
        resize(std::min(capacity_, std::max(2 * size_, used_ + need)));
        return true;
    }
    flush();
    if (need > capacity_) return false;
    if (need > size_) resize(std::min(capacity_, std::max(2 * size_, need)));
    return true;
}

void OutputBuffer::flush() {
    if (used_) out_.write(buf_.get(), static_cast<std::streamsize>(used_));
    written_ += used_;
    used_ = 0;
}

bool BlockEdits::add(uint32_t begin, uint32_t end, std::string_view text) {
    if (count_ >= kMaxEdits) {
        overflow_ = true;
        return false;
    }
    size_t at;
    if (text.data() >= arena_.data() && text.data() < arena_.data() + kArena) {
        at = static_cast<size_t>(text.data() - arena_.data());  // composed in scratch()
        used_ = std::max(used_, at + text.size());
    } else {
        if (text.size() > kArena - used_) {
            overflow_ = true;
            return false;
        }
        at = used_;
        copyBytes(arena_.data() + used_, text.data(), text.size());
        used_ += text.size();
    }
    edits_[count_] = {begin, end, static_cast<uint32_t>(at), static_cast<uint32_t>(text.size()),
                      static_cast<uint32_t>(count_)};
    if (count_ > 0 && before(edits_[count_], edits_[count_ - 1])) sorted_ = false;
    maxEnd_ = std::max({maxEnd_, begin, end});
    ++count_;
    return true;
}

char* BlockEdits::scratch(size_t need) {
    if (need > kArena - used_) {
        overflow_ = true;
        return nullptr;
    }
    return arena_.data() + used_;
}

void BlockEdits::apply(std::string_view line, OutputBuffer& out) {
    // Usually added in the order of the line already (the words, then what is appended after them): add() kept
    // track (as std::is_sorted would find).
    if (!sorted_) {
        std::sort(edits_.begin(), edits_.begin() + count_, before);
        sorted_ = true;
    }
    // Copied into the output buffer in one reservation of at most the line and all replacement text.
    const bool inLine = maxEnd_ <= line.size();
    char* at = inLine ? out.reserve(line.size() + used_) : nullptr;
    uint32_t pos = 0;
    if (at) {
        char* const start = at;
        for (int i = 0; i < count_; ++i) {
            const Edit& e = edits_[i];
            if (e.begin < pos) continue;
            at = copyBytes(at, line.data() + pos, e.begin - pos);
            at = copyBytes(at, arena_.data() + e.textBegin, e.textLen);
            pos = e.end;
        }
        at = copyBytes(at, line.data() + pos, line.size() - pos);
        out.commit(static_cast<size_t>(at - start));
        return;
    }
    pos = 0;
    for (int i = 0; i < count_; ++i) {
        const Edit& e = edits_[i];
        if (e.begin < pos) continue;  // overlapping edit: cannot happen with word spans; ignore defensively
        out.write(line.substr(pos, e.begin - pos));
        out.write(std::string_view(arena_.data() + e.textBegin, e.textLen));
        pos = e.end;
    }
    out.write(line.substr(pos));
}

}  // namespace cnccomp::postproc
