#include "postproc/line_reader.hpp"

#include <cstring>
#include <stdexcept>

namespace cnccomp::postproc {

LineReader::LineReader(std::istream& in, size_t capacity) : in_(in), buf_(capacity < 16 ? 16 : capacity) {}

void LineReader::fill() {
    if (eof_) return;
    if (begin_ > 0) {
        std::memmove(buf_.data(), buf_.data() + begin_, end_ - begin_);
        end_ -= begin_;
        begin_ = 0;
    }
    cacheValid_ = false;
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

size_t LineReader::findEnd() {
    // Each byte is searched at most once per character: the positions found are kept until consumed, so a file
    // with only '\r' endings does not rescan the buffer for a '\n' on every line (and vice versa).
    const char* base = buf_.data();
    auto search = [&](char c, size_t& cached) {
        if (cacheValid_ && cached >= begin_ && cached <= end_) return;
        const void* p = end_ > begin_ ? std::memchr(base + begin_, c, end_ - begin_) : nullptr;
        cached = p ? static_cast<size_t>(static_cast<const char*>(p) - base) : end_;
    };
    if (!cacheValid_) nl_ = cr_ = 0;
    search('\n', nl_);
    search('\r', cr_);
    cacheValid_ = true;
    return nl_ < cr_ ? nl_ : cr_;
}

bool LineReader::next(Line& line) {
    for (;;) {
        const char* base = buf_.data();
        const size_t p = findEnd();
        // A '\r' as the buffer's last byte may be the first half of "\r\n": read on before deciding.
        const bool crAtEdge = p < end_ && base[p] == '\r' && p + 1 == end_ && !eof_;
        if (p < end_ && !crAtEdge) {
            size_t after = p + 1;
            if (base[p] == '\r') {
                if (after < end_ && base[after] == '\n') ++after;
                else ++crOnly_;
            }
            if (!inLongLine_) ++lineNo_;
            line.text = {base + begin_, p - begin_};
            line.eol = {base + p, after - p};
            line.number = lineNo_;
            line.firstPiece = !inLongLine_;
            line.lastPiece = true;
            line.partial = inLongLine_;
            inLongLine_ = false;
            consumed_ += after - begin_;
            begin_ = after;
            return true;
        }
        const bool full = begin_ == 0 && end_ == buf_.size();
        if (full) {
            // No line ending within the whole buffer: hand out a piece (keep a trailing '\r' for the next piece).
            size_t take = end_;
            if (base[take - 1] == '\r') --take;
            if (!eof_ && in_.peek() == std::char_traits<char>::eof()) eof_ = true;  // to know the last piece
            line.firstPiece = !inLongLine_;
            if (!inLongLine_) ++lineNo_;
            line.text = {base, take};
            line.eol = {};
            line.number = lineNo_;
            line.lastPiece = eof_ && take == end_;  // the stream ends exactly at the buffer's end
            line.partial = true;
            inLongLine_ = !line.lastPiece;
            consumed_ += take;
            begin_ = take;
            return true;
        }
        if (eof_) {
            if (end_ == begin_) return false;
            if (!inLongLine_) ++lineNo_;
            line.text = {base + begin_, end_ - begin_};
            line.eol = {};
            line.number = lineNo_;
            line.firstPiece = !inLongLine_;
            line.lastPiece = true;
            line.partial = inLongLine_;
            inLongLine_ = false;
            consumed_ += end_ - begin_;
            begin_ = end_;
            return true;
        }
        fill();
    }
}

}  // namespace cnccomp::postproc
