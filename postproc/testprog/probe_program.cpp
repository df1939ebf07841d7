#include "postproc/testprog/probe_program.hpp"

#include <cctype>
#include <cmath>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/identification/sphere_probe.hpp"
#include "postproc/testprog/test_program.hpp"

namespace cnccomp::postproc::testprog {
using namespace cnccomp::identification;
using namespace cnccomp::measurement;
namespace {

constexpr const char* kLetters = "XYZABC";

class ProbeWriter {
public:
    ProbeWriter(const MachineModel& m, const ProbeProgramOptions& o) : m_(m), o_(o), d_(o.dialect) {}

    std::string text;
    /// LinuxCNC under G43.1 Z<L>: L (mm) taken off every Z word, as the ball-bar and R-test programs do
    /// (program_syntax.hpp, passToolLength): the joints stay where they were, and the generated kinematics component
    /// keeps the tool tip at L exact where the tool axis cannot follow (at A = 0 on an A/C table: without it, only the
    /// spindle reference point was exact and the stylus ball 120 mm below it was off by 8–10 µm on the real LinuxCNC).
    double zShift = 0;

    std::string num(double v, bool plus = false) const {
        std::string s = fmt::format("{:.{}f}", v, o_.decimals);
        if (s.find_first_not_of("-0.") == std::string::npos && s.front() == '-') s.erase(s.begin());
        if (plus && s.front() != '-') s.insert(s.begin(), '+');
        return s;
    }
    /// Axis words of the axes in `mask` (bit = machine axis), controller coordinates, X Y Z U V W A B C order.
    std::string words(const AxisVector& q, unsigned mask) const {
        const AxisVector c = m_.toController(q);
        std::string out;
        for (char l : std::string_view("XYZUVWABC")) {
            const int a = m_.axisIndex(std::string(1, l));
            if (a < 0 || !(mask & (1u << a))) continue;
            const bool rotary = m_.axisLink(a).kind == AxisKind::Rotary;
            if (!out.empty()) out += ' ';
            const double v = rotary ? c[a] / kDeg : l == 'Z' ? c[a] - zShift : c[a];
            out += fmt::format("{}{}", l, num(v, d_ == postproc::Dialect::Heidenhain));
        }
        return out;
    }
    unsigned all() const { return (1u << m_.axisCount()) - 1u; }
    unsigned linear() const {
        unsigned mask = 0;
        for (int a = 0; a < m_.axisCount(); ++a)
            if (m_.axisLink(a).kind == AxisKind::Linear) mask |= 1u << a;
        return mask;
    }
    void block(const std::string& s) {
        if (d_ == postproc::Dialect::Heidenhain) text += fmt::format("{} {}\n", n_++, s);
        else if (d_ == postproc::Dialect::Rs274ngc) text += s + "\n";
        else text += fmt::format("N{} {}\n", ++n_, s);
    }
    void comment(std::string_view c) {
        std::string s;
        for (char ch : c) {
            if (ch == '(') ch = '[';
            if (ch == ')') ch = ']';
            if (ch == ';' || ch == '\n') ch = ' ';
            s.push_back(d_ == postproc::Dialect::Fanuc ? static_cast<char>(std::toupper(static_cast<unsigned char>(ch))) : ch);
        }
        switch (d_) {
            case postproc::Dialect::Printer:  // refused by makeProbeProgram
            case postproc::Dialect::Rs274ngc:
            case postproc::Dialect::Fanuc: text += fmt::format("({})\n", s); break;
            case postproc::Dialect::Sinumerik: text += fmt::format("; {}\n", s); break;
            case postproc::Dialect::Heidenhain: block(fmt::format("; {}", s)); break;
        }
    }
    void rapid(const AxisVector& q, unsigned mask) {
        if (d_ == postproc::Dialect::Heidenhain) block(fmt::format("L {} R0 FMAX", words(q, mask)));
        else block(fmt::format("G0 {}", words(q, mask)));
    }

    /// The probing move and its result line.
    void probe(int pose, int touch, const AxisVector& from, const AxisVector& to, const Vec3& normal, double feed,
               double distance) {
        const std::string f = fmt::format("{:g}", feed);
        switch (d_) {
            case postproc::Dialect::Printer:  // refused by makeProbeProgram
            case postproc::Dialect::Rs274ngc:
                block(kSettleDwell);  // before every probing move: see probe_program.hpp, "LinuxCNC's stale DONE"
                block(fmt::format("G38.3 {} F{}", words(to, linear()), f));
                if (zShift != 0) {
                    // #5063 is in the program's coordinates, i.e. less the tool length: the log carries the machine Z.
                    block(fmt::format("#100=[#5063+{}]", num(zShift)));
                    block(fmt::format("(LOG,TOUCH {} {} #5070 #5061 #5062 #100 #5064 #5065 #5066)", pose, touch));
                } else {
                    block(fmt::format("(LOG,TOUCH {} {} #5070 #5061 #5062 #5063 #5064 #5065 #5066)", pose, touch));
                }
                break;
            case postproc::Dialect::Fanuc:
                block(fmt::format("#100={} #101={}", pose, touch));
                block(fmt::format("G31 {} F{}", words(to, linear()), f));
                block("DPRNT[TOUCH*#100[40]*#101[20]" + fanucVariables() + "]");
                break;
            case postproc::Dialect::Sinumerik:
                block(fmt::format("MEAS=1 G01 {} F{}", words(to, linear()), f));
                block("STOPRE");
                block(fmt::format("LINE=\"TOUCH {} {} \"<<$AC_MEA[1]{}", pose, touch, sinumerikValues()));
                block(fmt::format("WRITE(ERR,\"{}\",LINE)", sinumerikFile()));
                break;
            case postproc::Dialect::Heidenhain: {
                // Cycle 4 probes from the current position along the incremental vector, at most DIST mm.
                const Kinematics nominal(m_);
                (void)from;
                block("TCH PROBE 4.0 MEASURING IN 3-D");
                block("TCH PROBE 4.1 Q20");
                // The direction in the machine's linear axes: the commanded move from the approach to the target.
                const AxisVector c0 = m_.toController(from), c1 = m_.toController(to);
                std::string v;
                for (char l : std::string_view("XYZ")) {
                    const int a = m_.axisIndex(std::string(1, l));
                    if (a >= 0) v += fmt::format("{}I{}{}", v.empty() ? "" : " ", l, num(c1[a] - c0[a], true));
                }
                block("TCH PROBE 4.2 " + v);
                block(fmt::format("TCH PROBE 4.3 DIST+{} F{} TL+0", num(distance), f));
                (void)normal;
                for (int k = 0; k < 3; ++k) {
                    const int a = m_.axisIndex(std::string(1, "ABC"[k]));
                    block(fmt::format("Q{} = {}", 4 + k, a >= 0 ? num(c0[a] / kDeg, true) : num(0.0, true)));
                }
                block(fmt::format("Q100 = {}", pose));
                block(fmt::format("Q101 = {}", touch));
                block(fmt::format("FN 16: F-PRINT TNC:\\PROBE.A / TNC:\\{}", o_.log));
                break;
            }
        }
    }

    /// Fanuc: " *#5061[44]" … for X Y Z A B C (an axis the machine lacks prints #102 = 0).
    std::string fanucVariables() const {
        std::string s;
        int controlled = 0;
        std::vector<int> number(6, 0);
        for (char l : std::string_view("XYZABC")) {
            const int a = m_.axisIndex(std::string(1, l));
            if (a >= 0) number[std::string_view(kLetters).find(l)] = ++controlled;
        }
        for (int k = 0; k < 6; ++k)
            s += number[static_cast<size_t>(k)] ? fmt::format("*#{}[{}]", 5060 + number[static_cast<size_t>(k)],
                                                              k < 3 ? "44" : "34")
                                                : "*#102[10]";
        return s;
    }
    std::string sinumerikValues() const {
        std::string s;
        for (int k = 0; k < 6; ++k) {
            const int a = m_.axisIndex(std::string(1, kLetters[k]));
            s += a >= 0 ? fmt::format("<<\" \"<<$AA_MM[{}]", kLetters[k]) : "<<\" 0\"";
        }
        return s;
    }
    std::string sinumerikFile() const {
        std::string s;
        for (char c : o_.log) s.push_back(std::isalnum(static_cast<unsigned char>(c)) ? static_cast<char>(std::toupper(static_cast<unsigned char>(c))) : '_');
        return s;
    }

    int n_ = 0;
    const MachineModel& m_;
    const ProbeProgramOptions& o_;
    postproc::Dialect d_;
};

}  // namespace

std::string probeProgramFileName(postproc::Dialect d) {
    return d == postproc::Dialect::Heidenhain ? "PROBE.h" : std::string("probe") + programExtension(d);
}

ProbeProgram makeProbeProgram(const MachineModel& m, const MeasurementPlan& plan, const ProbeProgramOptions& o) {
    if (plan.sphereRuns.empty()) throw ModelError("the plan has no sphere runs (<sphere>) to probe");
    if (o.decimals < 3 || o.decimals > 9) throw ModelError("--decimals must be 3 .. 9");
    if (o.log.empty() || o.log.find_first_of("(),;\"\\/ \t") != std::string::npos)
        throw ModelError(fmt::format("--probe-log '{}': a plain file name without ( ) , ; \" \\ / or blanks", o.log));
    for (const SphereRun& r : plan.sphereRuns)
        if (!(r.feed > 0) || r.feed > 1e5) throw ModelError(fmt::format("sphere run '{}': feed must be 0 .. 100000 mm/min", r.name));
    const SpherePlanCommands cmds = sphereCommands(m, plan.sphereRuns);
    if (o.dialect == postproc::Dialect::Printer)
        throw ModelError(fmt::format("probing programs are written in {}, not for a printer",
                                     postproc::dialectNames(postproc::DialectUse::Write)));
    ProbeProgram out;
    ProbeWriter w(m, o);
    const postproc::Dialect d = o.dialect;
    const std::string name = "PROBE";
    // Header.
    if (d == postproc::Dialect::Fanuc) {
        w.text += "%\n";
        w.text += "O2000 (CNCCOMP SPHERE PROBING)\n";
    } else if (d == postproc::Dialect::Heidenhain) {
        w.block(fmt::format("BEGIN PGM {} MM", name));
    }
    w.comment(fmt::format("cnccomp sphere probing: machine {} plan {}", o.machineFile.empty() ? m.name : o.machineFile,
                          o.planFile));
    w.comment(kKinematicsModeLine);
    int touches = 0;
    for (const SphereRunCommands& rc : cmds.runs) touches += static_cast<int>(rc.poses.size()) * rc.run.touchesPerPose();
    w.comment(fmt::format("{} poses, {} touches; result file {}: one line per touch TOUCH <pose> <touch> {}X Y Z A B C",
                          cmds.poseCount(), touches, o.log, d == postproc::Dialect::Fanuc || d == postproc::Dialect::Heidenhain ? "" : "<flag 1 triggered 0 missed> "));
    for (const SphereRunCommands& rc : cmds.runs)
        w.comment(fmt::format("sphere {}: centre {:g} {:g} {:g} mm diameter {:g} stylus {:g} tool length {:g} approach {:g} "
                              "feed {:g} clearance {:g}",
                              rc.run.name, rc.run.centre.x(), rc.run.centre.y(), rc.run.centre.z(), rc.run.diameter,
                              rc.run.stylusDiameter, rc.run.toolLength, rc.run.approach, rc.run.feed, rc.run.clearance));
    const AxisVector zero = AxisVector::Zero(m.axisCount());
    switch (d) {
        case postproc::Dialect::Printer:  // refused by makeProbeProgram
        case postproc::Dialect::Rs274ngc:
            w.block("G17 G21 G40 G49 G80 G90 G94 G92.1");
            w.block("G61");                                 // exact path: the rapids between touches are not blended
            w.block("G10 L2 P1 " + w.words(m.fromController(zero), w.all()));  // G54 = machine coordinates
            w.block("G54");
            w.block(fmt::format("(LOGOPEN,{})", o.log));
            break;
        case postproc::Dialect::Fanuc:
            w.block("G17 G21 G40 G49 G80 G90 G94");
            w.block("G10 L2 P1 " + w.words(m.fromController(zero), w.all()));
            w.block("G54");
            w.block("#102=0");
            w.block("POPEN");
            break;
        case postproc::Dialect::Sinumerik:
            w.block("DEF STRING[250] LINE");
            w.block("DEF INT ERR");
            w.block("G17 G71 G40 G90 G94 D0");
            w.block("G500");
            w.block("G60");                                 // exact stop
            break;
        case postproc::Dialect::Heidenhain:
            w.block("TOOL CALL 0 Z");
            w.block("CYCL DEF 7.0 DATUM SHIFT");
            w.block("CYCL DEF 7.1 X+0");
            w.block("CYCL DEF 7.2 Y+0");
            w.block("CYCL DEF 7.3 Z+0");
            w.comment("[G] TCH PROBE 4 MEASURING IN 3-D block syntax (4.1 result Q, 4.2 incremental vector, 4.3 DIST F TL)");
            w.comment("results from Q115-Q117: spindle position at the contact (TNC 640 preassigned Q parameters)");
            w.comment("[G] FN 16 appends each output to the file when the program writes it again");
            break;
    }
    const unsigned park = 1u << cmds.parkAxis;
    const bool passToolLength = d == postproc::Dialect::Rs274ngc && m.axisIndex("Z") >= 0;
    for (const SphereRunCommands& rc : cmds.runs) {
        if (passToolLength && rc.run.toolLength != w.zShift) {
            if (rc.run.toolLength != 0) w.block("G43.1 Z" + w.num(rc.run.toolLength));  // LinuxCNC G-code reference, G43.1
            else w.block("G49");
            w.zShift = rc.run.toolLength;
        }
        for (const SpherePoseCommand& pc : rc.poses) {
            std::string angles;
            for (const auto& [axis, deg] : pc.angles) angles += fmt::format(" {}={:g}", axis, deg);
            w.comment(fmt::format("POSE {} sphere {}{}", pc.planPose, rc.run.name, angles));
            AxisVector up = pc.safe;
            up[cmds.parkAxis] = cmds.parkValue;
            w.rapid(up, park);
            w.rapid(up, w.all() & ~park);
            w.rapid(pc.safe, park);
            for (size_t t = 0; t < pc.touches.size(); ++t) {
                const SphereTouchCommand& tc = pc.touches[t];
                w.rapid(tc.above, w.linear());
                w.rapid(tc.approach, w.linear());
                w.probe(pc.planPose, static_cast<int>(t), tc.approach, tc.target, tc.normal, rc.run.feed,
                        2.0 * rc.run.approach);
                w.rapid(tc.approach, w.linear());
                w.rapid(tc.above, w.linear());
                out.targets.push_back({pc.planPose, static_cast<int>(t), tc.approach, tc.target});
                ++out.touches;
            }
            w.rapid(pc.safe, w.linear());
            w.rapid(up, park);
            ++out.poses;
        }
    }
    switch (d) {
        case postproc::Dialect::Printer:  // refused by makeProbeProgram
        case postproc::Dialect::Rs274ngc:
            if (w.zShift != 0) w.block("G49");
            w.block("(LOGCLOSE)");
            w.block("M2");
            break;
        case postproc::Dialect::Fanuc:
            w.block("PCLOS");
            w.block("M30");
            w.text += "%\n";
            break;
        case postproc::Dialect::Sinumerik: w.block("M30"); break;
        case postproc::Dialect::Heidenhain: w.block(fmt::format("END PGM {} MM", name)); break;
    }
    out.files.push_back({probeProgramFileName(d), w.text});
    if (d == postproc::Dialect::Heidenhain) {
        // FN 16 format file: the text with %-formats, then the Q parameters (TNC 640 Klartext manual, FN 16).
        // Q115–Q117: the spindle position at the contact (stylus length and ball radius not compensated), i.e. the
        // machine axes' values under TOOL CALL 0 and a zero datum (TNC 640 user's manual, "Preassigned Q parameters:
        // coordinates after probing during program run"); Q4–Q6: the pose's A B C as commanded.
        std::string a = "\"TOUCH %1.0LF %1.0LF %10.6LF %10.6LF %10.6LF %10.6LF %10.6LF %10.6LF\", Q100, Q101, Q115, Q116, Q117, "
                        "Q4, Q5, Q6;\n";
        out.files.push_back({"PROBE.A", a});
    }
    return out;
}

}  // namespace cnccomp::postproc::testprog
