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
    const auto before = [](const Edit& a, const Edit& b) {
        if (a.begin != b.begin) return a.begin < b.begin;
        // At the same position: a replacement that ends there first? No: replacements start there; insertions
        // (empty spans) go before replacements of the word that starts at the same byte.
        const bool ai = a.begin == a.end, bi = b.begin == b.end;
        if (ai != bi) return ai;
        return a.order < b.order;
    };
    // Usually added in the order of the line already (the words, then what is appended after them).
    if (!std::is_sorted(edits_.begin(), edits_.begin() + count_, before))
        std::sort(edits_.begin(), edits_.begin() + count_, before);
    // The edited line's length first: it is copied into the output buffer in one reservation.
    size_t total = 0;
    bool inLine = true;
    uint32_t pos = 0;
    for (int i = 0; i < count_ && inLine; ++i) {
        const Edit& e = edits_[i];
        if (e.begin < pos) continue;
        inLine = e.begin <= line.size() && e.end <= line.size();
        total += (e.begin - pos) + e.textLen;
        pos = e.end;
    }
    char* at = inLine ? out.reserve(total + (line.size() - pos)) : nullptr;
    if (at) {
        char* const start = at;
        pos = 0;
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
