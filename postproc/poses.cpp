#include "postproc/poses.hpp"

#include <istream>
#include <ostream>

#include <fmt/format.h>

#include "postproc/block_writer.hpp"
#include "postproc/klartext_reader.hpp"
#include "postproc/line_reader.hpp"
#include "postproc/correct_program.hpp"

namespace cnccomp::postproc {

PosesSummary writePoses(const AxisLayout& layout, std::istream& in, std::ostream& csv, const PosesOptions& options) {
    PosesSummary s;
    LineReader reader(in, options.bufferSize);
    const std::string_view head = reader.head();
    checkTextHead(head, options.inputName);
    s.dialect = options.dialect ? *options.dialect : detectDialect(head).dialect;
    if (s.dialect == Dialect::Heidenhain) return writeKlartextPoses(layout, reader, csv, options);
    Interpreter interp(layout, InterpreterOptions{s.dialect, options.setup, options.rotaryShortest, options.tcpOnM,
                                                  options.tcpOffM});
    OutputBuffer out(csv);
    out.write("line,motion,X,Y,Z,A,B,C\n");
    LexedBlock b;
    BlockResult r;
    Line line;
    OverlongLine overlong;
    static constexpr char kColumns[] = {'X', 'Y', 'Z', 'A', 'B', 'C'};
    fmt::memory_buffer row;
    while (reader.next(line)) {
        const uint64_t no = line.number;
        if (line.firstPiece) ++s.lines;
        if (line.partial) {
            // The same rule as `correct`: an overlong line forgets what it may change, nothing more.
            if (line.firstPiece) overlong.reset();
            overlong.feed(line.text);
            if (line.lastPiece && overlong.code) {
                ++s.passedThrough;
                interp.forgetOverlong(overlong, r);
            }
            continue;
        }
        lexBlock(line.text, s.dialect, b, no == 1);
        interp.interpret(line.text, b, r);
        if (r.modeSwitch) {
            // Without the machine's kinematics the position cannot be carried into the other mode: rotary angles are
            // the same numbers in both, the linear positions are unknown until the program names them.
            const AxisMask rotary = layout.rotaryAxes();
            interp.setPosition(interp.position(), interp.known() & rotary);
        }
        const bool moveRow = r.kind == BlockKind::Move;
        if (r.kind == BlockKind::PassThrough) ++s.passedThrough;
        if (!moveRow && !(r.kind == BlockKind::PassThrough && r.words)) continue;
        if (moveRow) ++s.moves;
        ++s.rows;
        row.clear();
        const char* motion = "-";
        if (moveRow) motion = r.motion == Motion::Rapid ? "G0" : r.motion == Motion::Linear ? "G1" : r.motion == Motion::ArcCw ? "G2" : "G3";
        if (r.machineCoordinates) motion = "G53";
        fmt::format_to(std::back_inserter(row), "{},{}{}", no, motion, moveRow && r.mode != ProgramMode::Joints ? " TCP" : "");
        for (char c : kColumns) {
            const int a = layout.axis(c);
            if (a < 0 || !(r.endKnown & (1u << a))) {
                row.push_back(',');
                continue;
            }
            const double v = layout.rotary[a] ? r.end[a] / kDeg : r.end[a];
            fmt::format_to(std::back_inserter(row), ",{:.6f}", v == 0 ? 0.0 : v);
        }
        row.push_back('\n');
        out.write(std::string_view(row.data(), row.size()));
    }
    out.flush();
    return s;
}

}  // namespace cnccomp::postproc
