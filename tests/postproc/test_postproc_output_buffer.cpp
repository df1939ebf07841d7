// The output buffer of `correct` and `poses` (postproc/block_writer.hpp): whatever the pieces' sizes and the capacity,
// the stream receives the concatenation of the pieces in order, never holds back more than the capacity, and passes a
// piece larger than the capacity straight through. Oracle: the concatenation itself (a std::string built beside it).
// The storage grows from 4 KiB to the capacity as the output grows (not zero-filled at full capacity): the pieces
// here cross every growth step of the 1 MiB default and of small capacities.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "postproc/block_writer.hpp"

namespace cnccomp {
namespace {

std::string piece(std::mt19937& rng, size_t n) {
    std::string s(n, ' ');
    for (char& c : s) c = static_cast<char>('a' + rng() % 26);
    return s;
}

TEST(PostprocOutputBuffer, StreamGetsEveryPieceInOrderAndHoldsAtMostTheCapacity) {
    for (const size_t capacity : {size_t{0}, size_t{64}, size_t{100}, size_t{5000}, size_t{70000}, size_t{1} << 20}) {
        SCOPED_TRACE(capacity);
        const size_t held = std::max<size_t>(capacity, 64);  // the buffer's smallest capacity
        std::mt19937 rng(7);
        std::ostringstream out;
        std::string expected;
        {
            postproc::OutputBuffer b(out, capacity);
            for (int i = 0; i < 4000; ++i) {
                // Mostly block-sized pieces, now and then one larger than the small capacities, some empty.
                const size_t n = i % 97 == 0 ? 3000 + rng() % 9000 : i % 31 == 0 ? 0 : rng() % 120;
                const std::string s = piece(rng, n);
                b.write(s);
                expected += s;
                ASSERT_EQ(b.bytesWritten(), expected.size());
                ASSERT_LE(expected.size() - static_cast<size_t>(out.tellp()), held);  // never more than the capacity held back
            }
            b.flush();
        }
        EXPECT_EQ(out.str(), expected);
    }
}

TEST(PostprocOutputBuffer, NothingReachesTheStreamBeforeTheCapacityIsExceededOrFlush) {
    std::ostringstream out;
    postproc::OutputBuffer b(out, 10000);
    std::string expected;
    for (int i = 0; i < 99; ++i) {  // 9 900 bytes: held (crossing the 4 KiB and 8 KiB storage steps)
        const std::string s(100, static_cast<char>('0' + i % 10));
        b.write(s);
        expected += s;
    }
    EXPECT_TRUE(out.str().empty());
    b.write(std::string(200, 'x'));  // beyond the capacity: the held bytes go first, then this piece is held
    EXPECT_EQ(out.str(), expected);
    expected += std::string(200, 'x');
    b.write(std::string(20000, 'y'));  // larger than the capacity: the held bytes, then the piece itself
    expected += std::string(20000, 'y');
    EXPECT_EQ(out.str(), expected);
    b.write("z");
    EXPECT_EQ(out.str(), expected);
    b.flush();
    EXPECT_EQ(out.str(), expected + "z");
    EXPECT_EQ(b.bytesWritten(), expected.size() + 1);
}

// BlockEdits::apply copies the edited line into the buffer in one reservation, every span and word by copyBytes (sizes
// 0 to 16 by overlapping fixed-size moves, more by memcpy), and falls back to piecewise writes when the line exceeds
// the buffer's capacity. Oracle: the splice written out here with std::string (replacements and insertions in position
// order, insertions before a replacement starting at the same byte), over random lines and edits of every size from 0
// to 40 bytes, added in order or shuffled, into a large and a small buffer.
TEST(PostprocOutputBuffer, EditedLinesAreTheSpliceOfTheirEditsWhateverTheSizes) {
    std::mt19937 rng(11);
    for (const size_t capacity : {size_t{64}, size_t{1} << 20}) {
        SCOPED_TRACE(capacity);
        std::ostringstream out;
        std::string expected;
        postproc::OutputBuffer b(out, capacity);
        postproc::BlockEdits edits;
        for (int i = 0; i < 3000; ++i) {
            const std::string line = piece(rng, rng() % 200);
            // Disjoint spans in position order (some empty: insertions), each replaced by 0–40 bytes.
            struct Span {
                uint32_t begin, end;
                std::string text;
            };
            std::vector<Span> spans;
            uint32_t pos = 0;
            while (spans.size() < 12) {
                const uint32_t begin = pos + static_cast<uint32_t>(rng() % 20);
                if (begin > line.size()) break;
                const uint32_t end = std::min<uint32_t>(static_cast<uint32_t>(line.size()), begin + static_cast<uint32_t>(rng() % 12));
                spans.push_back({begin, end, std::string(rng() % 41, static_cast<char>('A' + rng() % 26))});
                pos = end + 1;  // not touching: replacements of neighbouring words have a separator between them
            }
            edits.clear();
            // Every other line's edits added out of order (apply sorts them: the same splice).
            std::vector<const Span*> order;
            for (const Span& s : spans) order.push_back(&s);
            if (i % 2) std::shuffle(order.begin(), order.end(), rng);
            for (const Span* s : order) ASSERT_TRUE(edits.add(s->begin, s->end, s->text));
            std::string spliced;
            uint32_t at = 0;
            for (const Span& s : spans) {
                spliced += line.substr(at, s.begin - at);
                spliced += s.text;
                at = s.end;
            }
            spliced += line.substr(at);
            edits.apply(line, b);
            expected += spliced;
            ASSERT_EQ(b.bytesWritten(), expected.size());
        }
        b.flush();
        EXPECT_EQ(out.str(), expected);
    }
}

}  // namespace
}  // namespace cnccomp
