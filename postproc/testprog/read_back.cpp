#include "postproc/testprog/read_back.hpp"

#include <sstream>
#include <strings.h>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/text_util.hpp"
#include "postproc/klartext_correct.hpp"
#include "postproc/lexer.hpp"
#include "postproc/modal.hpp"
#include "postproc/poses.hpp"

namespace cnccomp::postproc::testprog {
using namespace cnccomp::io;

std::vector<PoseRow> readPoses(const MachineModel& m, std::string_view text, postproc::Dialect dialect, const std::string& source) {
    const postproc::AxisLayout layout = postproc::AxisLayout::fromMachine(m);
    postproc::PosesOptions o;
    o.dialect = dialect;
    o.inputName = source;
    std::istringstream in{std::string(text)};
    std::ostringstream csv;
    postproc::writePoses(layout, in, csv, o);
    static constexpr char kColumns[] = {'X', 'Y', 'Z', 'A', 'B', 'C'};
    std::vector<PoseRow> rows;
    std::istringstream lines(csv.str());
    std::string l;
    std::getline(lines, l);  // header
    while (std::getline(lines, l)) {
        std::vector<std::string_view> cells;
        std::string_view v = l;
        for (size_t p; (p = v.find(',')) != std::string_view::npos; v.remove_prefix(p + 1)) cells.push_back(v.substr(0, p));
        cells.push_back(v);
        if (cells.size() != 8) throw ModelError(fmt::format("{}: unexpected poses row '{}'", source, l));
        PoseRow r;
        r.line = static_cast<long>(parseNumber(cells[0]).value_or(0));
        r.motion = std::string(cells[1]);
        AxisVector p = AxisVector::Zero(m.axisCount());
        for (int c = 0; c < 6; ++c) {
            const int a = m.axisIndex(std::string(1, kColumns[c]));
            if (a < 0 || cells[2 + c].empty()) continue;
            const double value = parseNumber(cells[2 + c]).value_or(0.0);
            p[a] = m.axisLink(a).kind == AxisKind::Rotary ? value * kDeg : value;
            r.known |= 1u << a;
        }
        r.q = m.fromController(p);
        rows.push_back(std::move(r));
    }
    return rows;
}

std::vector<AxisVector> readProbeTargets(const MachineModel& m, std::string_view text, postproc::Dialect dialect,
                                         const std::string& source) {
    std::vector<AxisVector> out;
    AxisVector cur = AxisVector::Zero(m.axisCount());  // controller coordinates (mm, rad)
    double zOffset = 0;                                  // the active G43.1 tool length (LinuxCNC), mm
    const auto set = [&](char letter, double value) {
        const int a = m.axisIndex(std::string(1, letter));
        if (a >= 0) cur[a] = m.axisLink(a).kind == AxisKind::Rotary ? value * kDeg : value;
    };
    std::istringstream in{std::string(text)};
    std::string raw;
    long line = 0;
    while (std::getline(in, raw)) {
        ++line;
        std::string_view l = trim(raw);
        if (dialect == postproc::Dialect::Heidenhain) {
            // "<n> L X+1.0 Y+2.0 Z+3.0 R0 FMAX", "<n> TCH PROBE 4.2 IX+0.1 IY-0.2 IZ+0.0"
            std::istringstream w{std::string(l)};
            std::vector<std::string> t;
            for (std::string s; w >> s;) t.push_back(s);
            if (t.size() >= 2 && t[1] == "L") {
                for (size_t i = 2; i < t.size(); ++i)
                    if (t[i].size() > 1 && std::string_view("XYZABC").find(t[i][0]) != std::string_view::npos)
                        if (const auto v = parseNumber(std::string_view(t[i]).substr(1))) set(t[i][0], *v);
            } else if (t.size() >= 4 && t[1] == "TCH" && t[2] == "PROBE" && t[3] == "4.2") {
                AxisVector target = cur;
                for (size_t i = 4; i < t.size(); ++i) {
                    const auto v = t[i].size() > 2 && t[i][0] == 'I' ? parseNumber(std::string_view(t[i]).substr(2)) : std::nullopt;
                    const int a = t[i].size() > 2 ? m.axisIndex(std::string(1, t[i][1])) : -1;
                    if (!v || a < 0) throw InputError(source, static_cast<int>(line), fmt::format("'{}' is not an incremental axis word", t[i]));
                    target[a] += *v;
                }
                out.push_back(m.fromController(target));
            }
            continue;
        }
        std::string code(l);
        bool probe = false;
        if (dialect == postproc::Dialect::Sinumerik && code.rfind("N", 0) == 0 && code.find(" MEAS=") != std::string::npos) {
            const size_t p = code.find(" MEAS=");
            const size_t e = code.find(' ', p + 1);
            code.erase(p, e - p);  // the measuring keyword; the rest is a G01 block
            probe = true;
        }
        postproc::LexedBlock b;
        postproc::lexBlock(code, dialect, b, line == 1);
        bool motion = false;
        for (int i = 0; i < b.count; ++i) {
            const postproc::Word& w = b.words[static_cast<size_t>(i)];
            if (w.letter != 'G' || w.kind != postproc::ValueKind::Number) continue;
            if (dialect == postproc::Dialect::Rs274ngc && std::abs(w.value - 43.1) < 1e-9) {
                // G43.1 Z<L> (LinuxCNC dynamic tool length): L is added to every later Z word.
                for (int k = 0; k < b.count; ++k)
                    if (b.words[static_cast<size_t>(k)].letter == 'Z') zOffset = b.words[static_cast<size_t>(k)].value;
            }
            if (dialect == postproc::Dialect::Rs274ngc && w.value == 49) zOffset = 0;
            if (w.value == 0 || w.value == 1) motion = true;
            if (dialect == postproc::Dialect::Rs274ngc && w.value >= 38.15 && w.value <= 38.55) probe = true;
            if (dialect == postproc::Dialect::Fanuc && w.value == 31) probe = true;
        }
        if (!motion && !probe) continue;
        if (b.flags & postproc::kNotEvaluable)
            throw InputError(source, static_cast<int>(line), fmt::format("a motion block that cannot be evaluated ({})",
                                                                         postproc::lexFlagReason(b.flags)));
        for (int i = 0; i < b.count; ++i) {
            const postproc::Word& w = b.words[static_cast<size_t>(i)];
            if (std::string_view("XYZABC").find(w.letter) != std::string_view::npos) set(w.letter, w.letter == 'Z' ? w.value + zOffset : w.value);
        }
        if (probe) out.push_back(m.fromController(cur));
    }
    return out;
}

namespace {

struct Marker {
    long line = 0;
    int pass = 0;
    bool begin = false;
    std::string label;
};

/// A block with a number: ISO "N123 …", Klartext "12 …" (not one `correct` inserted: those end with its comment).
bool numberedBlock(std::string_view line, postproc::Dialect d) {
    line = trim(line);
    if (line.empty()) return false;
    if (d == postproc::Dialect::Heidenhain) {
        const std::string_view mark = postproc::kKlartextInsertedComment;
        const bool inserted = line.size() >= mark.size() && line.substr(line.size() - mark.size()) == mark;
        return std::isdigit(static_cast<unsigned char>(line.front())) && !inserted;
    }
    return (line.front() == 'N' || line.front() == 'n') && line.size() > 1 && std::isdigit(static_cast<unsigned char>(line[1]));
}

bool isMove(const PoseRow& r) { return r.motion == "G0" || r.motion == "G1" || r.motion == "G2" || r.motion == "G3"; }

}  // namespace

ProgramCommands readTestProgram(const MachineModel& m, const RunMotion& motion, std::string_view text, postproc::Dialect dialect,
                                const std::string& source) {
    const std::vector<PoseRow> rows = readPoses(m, text, dialect, source);
    std::vector<std::string_view> lines;
    for (std::string_view v = text; !v.empty();) {
        const size_t e = v.find('\n');
        lines.push_back(v.substr(0, e));
        if (e == std::string_view::npos) break;
        v.remove_prefix(e + 1);
    }
    long setupLine = 0;
    std::vector<Marker> markers;
    for (size_t i = 0; i < lines.size(); ++i) {
        const std::string_view l = lines[i];
        const size_t at = l.find("CNCCOMP ");
        if (at == std::string_view::npos) continue;
        std::istringstream words{std::string(l.substr(at + 8))};
        std::string w1, w2, w3, w4;
        words >> w1 >> w2 >> w3 >> w4;
        const long no = static_cast<long>(i) + 1;
        if (w1.rfind("SETUP", 0) == 0) setupLine = no;
        if (w1 == "PASS") {
            Marker mk;
            mk.line = no;
            mk.pass = static_cast<int>(parseNumber(w2).value_or(0));
            mk.begin = w4.rfind("BEGIN", 0) == 0;
            for (const char* label : {"CW", "CCW", "forward", "reverse"})
                if (mk.begin && strcasecmp(w3.c_str(), label) == 0) mk.label = label;
            markers.push_back(mk);
        }
    }
    const unsigned all = m.axisCount() >= 32 ? ~0u : (1u << m.axisCount()) - 1u;
    const auto complete = [&](const PoseRow& r, long line) {
        if ((r.known & all) != all)
            throw InputError(source, static_cast<int>(line), "a sweep point where an axis position is not known");
        return r.q;
    };
    const auto lastMoveBefore = [&](long line, const char* what) -> const PoseRow& {
        const PoseRow* found = nullptr;
        for (const PoseRow& r : rows)
            if (r.line < line && isMove(r)) found = &r;
        if (!found) throw InputError(source, static_cast<int>(line), fmt::format("no move reaches the {}", what));
        return *found;
    };
    if (setupLine == 0) throw InputError(source, 0, "no 'CNCCOMP SETUP' marker: not a cnccomp test program");
    ProgramCommands out;
    const PoseRow& setup = lastMoveBefore(setupLine, "setup pose");
    out.setup = complete(setup, setup.line);
    out.setupLine = setup.line;
    const size_t n = motion.points.size();
    for (int k = 1; k <= 2; ++k) {
        const Marker* b = nullptr;
        const Marker* e = nullptr;
        for (const Marker& mk : markers)
            if (mk.pass == k) (mk.begin ? b : e) = &mk;
        if (!b || !e || e->line < b->line)
            throw InputError(source, 0, fmt::format("markers 'CNCCOMP PASS {} … BEGIN' and 'CNCCOMP PASS {} END' missing", k, k));
        PassCommands pass;
        pass.label = b->label;
        const PoseRow& first = lastMoveBefore(b->line, "first sweep point");
        pass.q.push_back(complete(first, first.line));
        pass.lines.push_back(first.line);
        // Groups: each numbered block between the markers and the lines that follow it (pieces of a split block).
        std::vector<long> starts;
        for (long l = b->line + 1; l < e->line; ++l)
            if (numberedBlock(lines[static_cast<size_t>(l - 1)], dialect)) starts.push_back(l);
        for (size_t g = 0; g < starts.size(); ++g) {
            const long end = g + 1 < starts.size() ? starts[g + 1] : e->line;
            const PoseRow* last = nullptr;
            for (const PoseRow& r : rows) {
                if (r.line < starts[g] || r.line >= end) continue;
                if (r.motion == "-" || r.motion == "G53")
                    throw InputError(source, static_cast<int>(r.line), "a block between the sweep markers that cannot be evaluated");
                if (isMove(r)) last = &r;
            }
            if (!last) continue;  // dwell, comment
            pass.q.push_back(complete(*last, last->line));
            pass.lines.push_back(last->line);
        }
        if (pass.q.size() != n)
            throw InputError(source, static_cast<int>(b->line),
                             fmt::format("pass {} reaches {} points, the plan's run '{}' has {}", k, pass.q.size(), motion.name, n));
        // Direction: the assignment of the plan's points that the commands follow more closely (a whole turn starts
        // and ends on the same pose, so the whole pass decides).
        double dForward = 0, dReverse = 0;
        for (size_t i = 0; i < n; ++i) {
            dForward += (pass.q[i] - motion.at(motion.points[i])).norm();
            dReverse += (pass.q[i] - motion.at(motion.points[n - 1 - i])).norm();
        }
        const bool forward = dForward <= dReverse;
        for (size_t i = 0; i < n; ++i) {
            const size_t idx = forward ? i : n - 1 - i;
            pass.index.push_back(idx);
            pass.t.push_back(motion.points[idx]);
        }
        out.passes.push_back(std::move(pass));
    }
    return out;
}

void passSamples(const RunMotion& motion, const PassCommands& pass, std::vector<double>& t, std::vector<AxisVector>& q) {
    t.clear();
    q.clear();
    for (size_t i = 0; i < pass.index.size(); ++i)
        if (pass.index[i] < motion.sampleCount) {
            t.push_back(pass.t[i]);
            q.push_back(pass.q[i]);
        }
}

}  // namespace cnccomp::postproc::testprog
