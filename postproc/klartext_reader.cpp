#include "postproc/klartext_reader.hpp"

#include <istream>
#include <ostream>
#include <string>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/text_util.hpp"
#include "postproc/block_writer.hpp"
#include "postproc/klartext_blocks.hpp"
#include "postproc/line_reader.hpp"

namespace cnccomp::postproc {
using namespace cnccomp::io;

PosesSummary writeKlartextPoses(const AxisLayout& layout, LineReader& lines, std::ostream& csv, const PosesOptions& options) {
    PosesSummary s;
    s.dialect = Dialect::Heidenhain;
    KlartextInterpreter interp(layout, options.setup, options.inputName);
    KlartextBlock b;
    OutputBuffer out(csv);
    out.write("line,motion,X,Y,Z,A,B,C\n");
    std::string logical, row;
    uint64_t no = 0, start = 0;
    bool pending = false;
    Line line;
    static constexpr char kColumns[] = {'X', 'Y', 'Z', 'A', 'B', 'C'};
    const auto flush = [&] {
        interp.interpret(logical, start, b);
        if (b.kind == KlartextKind::Unsupported) throw InputError(options.inputName, static_cast<int>(start), b.reason);
        if (b.kind != KlartextKind::Move) return;
        const unsigned all = layout.all();
        const bool complete = (b.endKnown & all) == all;
        const char* motion = b.machine ? "G53"
                             : b.motion == Motion::Rapid ? "G0"
                             : b.motion == Motion::Linear ? "G1"
                             : b.motion == Motion::ArcCw ? "G2"
                                                         : "G3";
        if (!complete) motion = "-";
        s.rows++;
        if (complete) s.moves++;
        else s.passedThrough++;
        row.clear();
        fmt::format_to(std::back_inserter(row), "{},{}{}", start, motion, complete && b.mode != ProgramMode::Joints ? " TCP" : "");
        for (char c : kColumns) {
            const int a = layout.axis(c);
            if (a < 0 || !(b.endKnown & (1u << a))) {
                row.push_back(',');
                continue;
            }
            const double v = layout.rotary[a] ? b.end[a] / kDeg : b.end[a];
            fmt::format_to(std::back_inserter(row), ",{:.6f}", v == 0 ? 0.0 : v);
        }
        row.push_back('\n');
        out.write(row);
    };
    while (lines.next(line)) {
        ++no;
        ++s.lines;
        if (line.partial) throw InputError(options.inputName, static_cast<int>(no), "line longer than the read buffer");
        if (line.text.find('\0') != std::string_view::npos)
            throw InputError(options.inputName, static_cast<int>(no), "binary data in a Klartext program");
        if (!pending) {
            logical.clear();
            start = no;
        } else {
            logical += '\n';
        }
        logical += line.text;
        const std::string_view t = trim(line.text);  // '~' at the end of the line (after a comment too): continued
        pending = !t.empty() && t.back() == '~';
        if (!pending) flush();
    }
    if (pending) flush();
    if (s.lines == 0) throw InputError(options.inputName, 0, "empty program");
    out.flush();
    return s;
}

PosesSummary writeKlartextPoses(const AxisLayout& layout, std::istream& in, std::ostream& csv, const PosesOptions& options) {
    LineReader lines(in, options.bufferSize);
    return writeKlartextPoses(layout, lines, csv, options);
}

}  // namespace cnccomp::postproc
