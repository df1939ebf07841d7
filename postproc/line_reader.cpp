#include "postproc/line_reader.hpp"

#include <cstring>
#include <stdexcept>

namespace cnccomp::pp {

LineReader::LineReader(std::istream& in, size_t capacity) : in_(in), buf_(capacity < 16 ? 16 : capacity) {}

void LineReader::fill() {
    if (eof_) return;
    if (begin_ > 0) {
        std::memmove(buf_.data(), buf_.data() + begin_, end_ - begin_);
        end_ -= begin_;
        begin_ = 0;
    }
    while (end_ < buf_.size() && !eof_) {
        in_.read(buf_.data() + end_, static_cast<std::streamsize>(buf_.size() - end_));
        const auto got = in_.gcount();
        end_ += static_cast<size_t>(got);
        if (!in_) {
            if (in_.bad()) throw std::runtime_error("read error");
            eof_ = true;
        }
        if (got == 0 && !eof_) eof_ = true;
    }
}

std::string_view LineReader::head() {
    if (end_ == begin_) fill();
    return {buf_.data() + begin_, end_ - begin_};
}

bool LineReader::next(Line& line) {
    for (;;) {
        const char* base = buf_.data();
        const void* nl = end_ > begin_ ? std::memchr(base + begin_, '\n', end_ - begin_) : nullptr;
        if (nl) {
            const size_t p = static_cast<size_t>(static_cast<const char*>(nl) - base);
            size_t textEnd = p;
            if (textEnd > begin_ && base[textEnd - 1] == '\r') --textEnd;
            line.text = {base + begin_, textEnd - begin_};
            line.eol = {base + textEnd, p + 1 - textEnd};
            line.partial = inLongLine_;
            inLongLine_ = false;
            consumed_ += p + 1 - begin_;
            begin_ = p + 1;
            return true;
        }
        const bool full = begin_ == 0 && end_ == buf_.size();
        if (full) {
            // No line ending within the whole buffer: hand out a piece (keep a trailing '\r' for the next piece).
            size_t take = end_;
            if (base[take - 1] == '\r') --take;
            line.text = {base, take};
            line.eol = {};
            line.partial = true;
            inLongLine_ = true;
            consumed_ += take;
            begin_ = take;
            return true;
        }
        if (eof_) {
            if (end_ == begin_) return false;
            line.text = {base + begin_, end_ - begin_};
            line.eol = {};
            line.partial = inLongLine_;
            inLongLine_ = false;
            consumed_ += end_ - begin_;
            begin_ = end_;
            return true;
        }
        fill();
    }
}

}  // namespace cnccomp::pp
