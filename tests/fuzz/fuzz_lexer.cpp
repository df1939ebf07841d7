// libFuzzer target for the G-code lexer layer: the streaming line reader (with a tiny buffer, so overlong
// lines are exercised), dialect detection, the block lexer in every dialect, and number parsing/formatting.
// Checks invariants that the writer relies on: word spans inside the line and in order, codeEnd inside the
// line, the reader giving back every byte, formatted numbers parsing back to their rounded value.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <sstream>
#include <string>

#include "postproc/dialect.hpp"
#include "postproc/lexer.hpp"
#include "postproc/line_reader.hpp"
#include "cnccomp/io/number_format.hpp"

using namespace cnccomp;
using namespace cnccomp::postproc;
using namespace cnccomp::io;

namespace {
void check(bool ok) {
    if (!ok) std::abort();
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string input(reinterpret_cast<const char*>(data), size);
    (void)detectDialect(input);
    std::istringstream in(input);
    LineReader reader(in, 64);
    Line line;
    std::string rebuilt;
    LexedBlock b;
    OverlongLine overlong;
    bool first = true;
    uint64_t lastNumber = 0;
    bool inPieces = false;
    while (reader.next(line)) {
        rebuilt.append(line.text).append(line.eol);
        // Line numbers: +1 per line, the same for every piece of an overlong line.
        check(line.number == (inPieces ? lastNumber : lastNumber + 1));
        check(line.firstPiece == !inPieces);
        lastNumber = line.number;
        inPieces = !line.lastPiece;
        if (line.partial) {
            if (line.firstPiece) overlong.reset();
            overlong.feed(line.text);
        }
        for (Dialect d : {Dialect::Rs274ngc, Dialect::Fanuc, Dialect::Sinumerik, Dialect::Printer}) {
            lexBlock(line.text, d, b, first);
            check(b.count >= 0 && b.count <= LexedBlock::kMaxWords);
            check(b.codeEnd <= line.text.size());
            uint32_t prev = 0;
            for (int i = 0; i < b.count; ++i) {
                const Word& w = b.words[i];
                check(w.begin >= prev && w.begin < w.end && w.end <= line.text.size());
                check(w.valueBegin >= w.begin && w.valueBegin <= w.end);
                check(w.letter >= 'A' && w.letter <= 'Z');
                if (w.kind == ValueKind::Number && !(b.flags & kBadNumber)) check(std::isfinite(w.value));
                prev = w.end;
            }
            for (int k = 0; k < b.identifierCount; ++k)
                check(b.identifiers[k].begin < b.identifiers[k].end && b.identifiers[k].end <= line.text.size());
            (void)lexFlagReason(b.flags);
        }
        first = false;
        double v = 0;
        if (parseGcodeNumber(line.text, v)) {
            char buf[kMaxNumberChars];
            for (int dec : {0, 3, 6}) {
                const NumberStyle st{dec, dec % 2 == 0, dec == 3, false, true};
                const size_t n = formatNumber(v, st, buf);
                check(n > 0 && n < kMaxNumberChars);
                double back = 0;
                if (std::fabs(v) < 1e12) {
                    check(parseGcodeNumber(std::string_view(buf, n), back));
                    check(back == roundToStyle(v, st));
                }
            }
        }
    }
    check(rebuilt == input);
    check(!inPieces);
    return 0;
}
