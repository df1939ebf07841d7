// What the first bytes of a program say before it is read: whether it is text at all, and the tool length a test
// program's header names (`correct` and `poses`).
#include <cctype>
#include <cmath>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/text_util.hpp"
#include "postproc/correct_program.hpp"

namespace cnccomp::postproc {
using namespace cnccomp::io;

std::optional<HeaderToolLength> toolLengthFromHeader(std::string_view head) {
    static constexpr std::string_view kHint = "cnccomp correct --tool-length ";
    uint64_t line = 0;
    while (!head.empty() && line < 200) {
        ++line;
        const size_t eol = head.find('\n');
        const std::string_view text = head.substr(0, eol);
        head = eol == std::string_view::npos ? std::string_view{} : head.substr(eol + 1);
        for (size_t i = 0; i + kHint.size() <= text.size(); ++i) {
            size_t k = 0;
            while (k < kHint.size() &&
                   std::tolower(static_cast<unsigned char>(text[i + k])) == static_cast<unsigned char>(kHint[k]))
                ++k;
            if (k < kHint.size()) continue;
            std::string_view rest = text.substr(i + k);
            size_t n = 0;
            while (n < rest.size() && (std::isdigit(static_cast<unsigned char>(rest[n])) || rest[n] == '.' ||
                                       rest[n] == '-' || rest[n] == '+' || rest[n] == 'e' || rest[n] == 'E'))
                ++n;
            const auto v = parseNumber(rest.substr(0, n));
            if (v && std::isfinite(*v) && std::fabs(*v) <= 1e5) return HeaderToolLength{*v, line};
        }
    }
    return std::nullopt;
}

void checkTextHead(std::string_view head, const std::string& name) {
    if (head.empty()) throw InputError(name, 0, "the program is empty (no bytes)");
    size_t control = 0;
    int line = 1;
    for (size_t i = 0; i < head.size(); ++i) {
        const unsigned char c = static_cast<unsigned char>(head[i]);
        if (c == '\n') ++line;
        if (c == 0)
            throw InputError(name, line,
                             fmt::format("binary data (a NUL byte at byte {}): not a G-code text file", i + 1));
        if (c < 0x20 && c != '\n' && c != '\r' && c != '\t' && c != '\f' && c != '\v' && c != 0x1a) ++control;
    }
    if (control * 20 > head.size())
        throw InputError(name, 0,
                         fmt::format("binary data ({} control bytes in the first {}): not a G-code text file", control,
                                     head.size()));
}

}  // namespace cnccomp::postproc
