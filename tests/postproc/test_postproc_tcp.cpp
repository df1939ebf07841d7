// Tool-centre-point (TCP) programs: LinuxCNC's 5-axis demos for the switchable xyzac-trt-kins sim (M428 on, M429
// off: impeller from ../shared/gcode-corpus, boat read in place from a fetched LinuxCNC tree) corrected in TCP mode and
// checked with models written here, independently of the corrector:
//  - the controller: xyzacKinematicsForward / Inverse transcribed from LinuxCNC src/emc/kinematics/trtfuncs.c
//    (conventional-directions 0, rot-points 0, y-offset 20, z-offset 10 as in
//    configs/sim/axis/vismach/5axis/table-rotary-tilting/xyzac-trt.ini; tool-offset = the active G43 length, 0 here);
//  - the erroneous machine: the link transforms composed by hand from README's definition (link = placement ·
//    E_location · motion, E = translation then rotation by the rotation vector (a, b, c));
//  - the programs: read with a small word scanner of this file (G0/G1/G2/G3, X Y Z A C I J, G17, G90, G91.1).
// The corrected program, run through the controller's inverse and the erroneous machine, must put the tool tip within
// 0.5 um of the nominal tool-tip path (the original program through the same controller and the nominal machine) at
// every end point and every segment midpoint (the controller interpolates the world point and the angles linearly).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <vector>

#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "postproc/correction.hpp"
#include "postproc/correct_program.hpp"
#include "test_postproc_xyzac.hpp"
#include "test_support.hpp"

namespace cnccomp::postproc {
using namespace cnccomp::io;
namespace {

using namespace cnccomp::test::xyzac;  // the independent controller and machine models

const char* kMachineXml = cnccomp::test::kXyzacTrtMachine;

// --- A word scanner for the demo programs --------------------------------------------------------------------------
struct Block {
    int line = 0;
    int motion = -1;  // 0 1 2 3
    World to;
    double i = 0, j = 0;
};

/// Moves between M428 and M429 (TCP mode), absolute X Y Z A C, incremental I J arc centres in G17.
std::vector<Block> tcpMoves(const std::string& program, const std::vector<double>& workOffset = {0, 0, 0}) {
    std::vector<Block> out;
    std::istringstream in(program);
    std::string s;
    bool tcp = false;
    int motion = -1, line = 0;
    World pos;
    while (std::getline(in, s)) {
        ++line;
        if (!s.empty() && s.back() == '\r') s.pop_back();
        const size_t semi = s.find(';');
        if (semi != std::string::npos) s.resize(semi);
        for (size_t p; (p = s.find('(')) != std::string::npos;) s.erase(p, s.find(')', p) - p + 1);
        Block b;
        b.line = line;
        bool axes = false, arcCentre = false;
        double m = -1;
        for (size_t k = 0; k < s.size();) {
            const char c = static_cast<char>(std::toupper(static_cast<unsigned char>(s[k])));
            if (!std::isalpha(static_cast<unsigned char>(c))) {
                ++k;
                continue;
            }
            size_t e = k + 1;
            while (e < s.size() && s[e] == ' ') ++e;
            size_t used = 0;
            const double v = std::stod(s.substr(e), &used);
            k = e + used;
            switch (c) {
                case 'G': if (v == 0 || v == 1 || v == 2 || v == 3) motion = static_cast<int>(v); break;
                case 'M': m = v; break;
                case 'X': pos.x = v + workOffset[0], axes = true; break;
                case 'Y': pos.y = v + workOffset[1], axes = true; break;
                case 'Z': pos.z = v + workOffset[2], axes = true; break;
                case 'A': pos.a = v, axes = true; break;
                case 'C': pos.c = v, axes = true; break;
                case 'I': b.i = v, arcCentre = true; break;
                case 'J': b.j = v, arcCentre = true; break;
                default: break;
            }
        }
        if (m == 428) tcp = true;
        if (m == 429) tcp = false;
        if (!tcp || !(axes || arcCentre)) continue;
        b.motion = motion;
        b.to = pos;
        out.push_back(b);
    }
    return out;
}

World lerp(const World& a, const World& b, double t) {
    return {a.x + t * (b.x - a.x), a.y + t * (b.y - a.y), a.z + t * (b.z - a.z), a.a + t * (b.a - a.a), a.c + t * (b.c - a.c)};
}

/// World position along a move at t: straight, or the G17 arc (x, y on the circle, the rest straight).
World along(const World& from, const Block& b, double t) {
    World w = lerp(from, b.to, t);
    if (b.motion != 2 && b.motion != 3) return w;
    const double cx = from.x + b.i, cy = from.y + b.j;
    const double r0 = std::hypot(from.x - cx, from.y - cy), r1 = std::hypot(b.to.x - cx, b.to.y - cy);
    const double t0 = std::atan2(from.y - cy, from.x - cx);
    double sweep = std::atan2(b.to.y - cy, b.to.x - cx) - t0;
    if (b.motion == 2) {
        while (sweep >= 0) sweep -= 2 * kPi;
    } else {
        while (sweep <= 0) sweep += 2 * kPi;
    }
    const double th = t0 + t * sweep, r = r0 + t * (r1 - r0);
    w.x = cx + r * std::cos(th);
    w.y = cy + r * std::sin(th);
    return w;
}

struct TcpCheck {
    double maxTip = 0, maxMid = 0, uncorrected = 0, maxAxisArcsec = 0;
    size_t inputMoves = 0, outputMoves = 0;
};

/// Distance from p to the nominal tool-tip path of one input move; the parameter of the closest point in `at`.
double distanceToNominal(const World& from, const Block& b, double L, const Vec3& p, double* at = nullptr) {
    return distanceToPath([&](double t) { return machineTip(trtInverse(along(from, b, t), 0), L, nullptr).tip; }, p, at);
}

TcpCheck checkTcp(const std::string& original, const std::string& corrected, double L, const Errors& e,
                  const std::vector<double>& offset = {0, 0, 0}) {
    const std::vector<Block> nom = tcpMoves(original, offset), act = tcpMoves(corrected, offset);
    TcpCheck c;
    c.inputMoves = nom.size();
    c.outputMoves = act.size();
    // Output moves in order: each lies on one of the next few input moves (split pieces share their input move).
    size_t s = 1;
    for (size_t k = 1; k < act.size(); ++k) {
        const Block& b = act[k];
        const World& from = act[k - 1].to;
        double bestWorst = HUGE_VAL, bestMid = 0, bestEnd = 0, bestAxis = 0;
        size_t bestIndex = s;
        const ToolTip end = machineTip(trtInverse(b.to, 0), L, &e);
        for (size_t cand = s; cand < std::min(nom.size(), s + 4); ++cand) {
            double t = 0;
            const double dEnd = distanceToNominal(nom[cand - 1].to, nom[cand], L, end.tip, &t);
            double dMid = 0;
            if (b.motion != 0) {
                const Vec3 mid = machineTip(trtInverse(along(from, b, 0.5), 0), L, &e).tip;
                dMid = distanceToNominal(nom[cand - 1].to, nom[cand], L, mid);
            }
            const double worst = std::max(dEnd, dMid);
            if (worst < bestWorst - 1e-12) {
                bestWorst = worst, bestIndex = cand, bestMid = dMid, bestEnd = dEnd;
                // Tool axis at the end point against the nominal one at the input move's end (the same end point)
                // or, for a piece of a split move, at the closest point of the nominal path.
                const ToolTip nEnd = machineTip(trtInverse(nom[cand].to, 0), L, nullptr);
                const Vec3 n = (nEnd.tip - end.tip).norm() < 1 * kUm
                                   ? nEnd.axis
                                   : machineTip(trtInverse(along(nom[cand - 1].to, nom[cand], t), 0), L, nullptr).axis;
                bestAxis = std::acos(std::clamp(n.dot(end.axis), -1.0, 1.0)) / kArcsec;
            }
            if (worst <= 0.5 * kUm) break;
        }
        c.maxTip = std::max(c.maxTip, bestEnd);
        c.maxMid = std::max(c.maxMid, bestMid);
        // Near A = 0 the tool axis is parallel to C: a tilt of C (EB0C) cannot be corrected there (see above).
        if (std::fabs(b.to.a) >= 10) c.maxAxisArcsec = std::max(c.maxAxisArcsec, bestAxis);
        s = bestIndex;
    }
    // The same program uncorrected on the erroneous machine (end points), and the tool axis of the corrected one.
    for (const Block& b : nom) {
        const ToolTip n = machineTip(trtInverse(b.to, 0), L, nullptr), a = machineTip(trtInverse(b.to, 0), L, &e);
        c.uncorrected = std::max(c.uncorrected, (n.tip - a.tip).norm());
    }
    return c;
}

struct SimFiles {
    test::ScratchDir dir{"pp-tcp"};
    std::string machine, deviations;
    SimFiles() {
        machine = dir.file("xyzac-trt.xml");
        deviations = dir.file("deviations.csv");
        test::writeText(machine, kMachineXml);
        test::writeText(deviations, kDeviationCsv);
    }
};

std::string correctTcp(const std::string& program, const SimFiles& st, double L, CorrectSummary& s, bool tcp = true,
                       double tolUm = 0.5) {
    const MachineModel m = readMachineXml(st.machine);
    const DeviationSet d = readDeviationCsv(st.deviations, m);
    CorrectOptions o;
    o.dialect = Dialect::Rs274ngc;
    o.setup.addToolLength(std::to_string(L));
    o.corrector.toleranceMm = tolUm * kUm;
    if (tcp) o.tcpOnM = 428, o.tcpOffM = 429;
    std::istringstream in(program);
    std::ostringstream out;
    s = correctProgram(m, d, in, out, o);
    return out.str();
}

TEST(PostprocTcp, ControllerModelMatchesLinuxCncTrtKinematics) {
    // Our TCP world frame and inverse against trtfuncs.c transcribed: random joints, tool offsets 0 and 35 mm.
    SimFiles st;
    const MachineModel m = readMachineXml(st.machine);
    Corrector corrector(m, DeviationSet(m));
    const int ax = m.requireAxis("X"), ay = m.requireAxis("Y"), az = m.requireAxis("Z"), aa = m.requireAxis("A"),
              ac = m.requireAxis("C");
    std::srand(5);
    for (int k = 0; k < 200; ++k) {
        auto u = [] { return 2.0 * std::rand() / RAND_MAX - 1.0; };
        const Joints j{u() * 150, u() * 80, u() * 100, -100 + 150 * (u() + 1) / 2, u() * 720};
        for (double dt : {0.0, 35.0}) {
            const World w = trtForward(j, dt);
            AxisVector c(5);
            c[ax] = j.x, c[ay] = j.y, c[az] = j.z, c[aa] = j.a * kDeg, c[ac] = j.c * kDeg;
            ProgramPoint p;
            corrector.toProgram(MoveSpace{ProgramMode::TcpAngles, dt, dt}, c, p);
            // LinuxCNC's world includes the tool offset in Z (canon adds it): the programmed point is world − dt.
            EXPECT_NEAR(p.p[ax], w.x, 1e-9);
            EXPECT_NEAR(p.p[ay], w.y, 1e-9);
            EXPECT_NEAR(p.p[az], w.z - dt, 1e-9);
            AxisVector back;
            p.p[az] = w.z - dt;
            ASSERT_TRUE(corrector.toJoints(MoveSpace{ProgramMode::TcpAngles, dt, dt}, p, c, back));
            const Joints ref = trtInverse(w, dt);
            EXPECT_NEAR(back[ax], ref.x, 1e-9);
            EXPECT_NEAR(back[ay], ref.y, 1e-9);
            EXPECT_NEAR(back[az], ref.z, 1e-9);
        }
    }
}

void expectTcpAccurate(const std::string& name, const std::string& program, double L, size_t minMoves,
                       uint64_t passThrough) {
    // Tool axis, 10 deg or more away from the singular pose A = 0, where the solution is exact (nothing is damped above
    // CorrectorOptions::singularSine, 5.7 deg): what is left is the written digits, half a digit (1e-4 deg) of A and of
    // C, 0.18 arcsec each (before the damping was confined to ill-conditioned poses: up to 1.4 arcsec). Closer to A = 0
    // the C correction a tilt of C needs grows as 1/sin A and is limited there.
    const double maxAxisArcsec = 0.6;
    SimFiles st;
    CorrectSummary s;
    const std::string out = correctTcp(program, st, L, s);
    const TcpCheck c = checkTcp(program, out, L, Errors{});
    std::printf("[ tcp      ] %-22s moves %zu -> %zu, end points %.4f um, midpoints %.4f um (uncorrected %.2f um), "
                "tool axis %.3f arcsec, split %llu\n",
                name.c_str(), c.inputMoves, c.outputMoves, c.maxTip / kUm, c.maxMid / kUm, c.uncorrected / kUm,
                c.maxAxisArcsec, static_cast<unsigned long long>(s.split));
    EXPECT_GE(c.inputMoves, minMoves);
    EXPECT_EQ(s.tcpMoves, s.moves) << formatSummary(s);
    EXPECT_GT(c.uncorrected, 10 * kUm) << "the deviations must matter, or this test proves nothing";
    EXPECT_LE(c.maxTip, 0.5 * kUm);
    EXPECT_LE(c.maxMid, 0.5 * kUm);
    EXPECT_LE(c.maxAxisArcsec, maxAxisArcsec);
    EXPECT_EQ(s.unconverged, 0u);
    EXPECT_EQ(s.passedThrough, passThrough) << formatSummary(s);
    // Read as joint positions (the words of M428 blocks as machine coordinates), the same program comes out wrong.
    CorrectSummary joint;
    const std::string wrong = correctTcp(program, st, L, joint, false);
    const TcpCheck w = checkTcp(program, wrong, L, Errors{});
    EXPECT_GT(w.maxTip, 5 * kUm) << "joint-space correction of a TCP program must not pass this check";
}

TEST(PostprocTcp, ImpellerDemoCorrectedInTcpMode) {
    const std::string path = test::sharedPath("gcode-corpus/impeller-7bl-xyzac.ngc");
    if (!std::filesystem::exists(path)) GTEST_SKIP() << "no " << path;
    expectTcpAccurate("impeller-7bl-xyzac.ngc", test::readText(path), 30.0, 4400, 0);
}

TEST(PostprocTcp, BoatDemoFromTheLinuxCncTreeCorrectedInTcpMode) {
    // Read in place (never copied into this repository): LinuxCNC's own demo as Debian's linuxcnc-uspace ships it with
    // the sample configurations (tools/deps.sh installs the package, so this runs in CI), else from a fetched LinuxCNC
    // repository.
    const std::string installed =
        "/usr/share/doc/linuxcnc/examples/sample-configs/sim/axis/vismach/5axis/table-rotary-tilting/demos/boat-xyzac.ngc";
    std::string program;
    if (std::filesystem::exists(installed)) {
        program = test::readText(installed);
    } else {
        const std::string git = "/work/.mirror/LinuxCNC+linuxcnc/repo";
        if (!std::filesystem::exists(git))
            GTEST_SKIP() << "neither " << installed << " (Debian package linuxcnc-uspace) nor a LinuxCNC mirror at " << git
                         << ": boat demo not checked";
        test::ScratchDir dir("pp-tcp-boat");
        const std::string file = dir.file("boat-xyzac.ngc");
        const std::string cmd = "git --git-dir=" + git +
                                " show HEAD:configs/sim/axis/vismach/5axis/table-rotary-tilting/demos/boat-xyzac.ngc > " +
                                file + " 2>/dev/null";
        if (std::system(cmd.c_str()) != 0 || std::filesystem::file_size(file) == 0)
            GTEST_SKIP() << "boat-xyzac.ngc not found in " << git;
        program = test::readText(file);
    }
    // One block passes through: "Z5" before the program has named X and Y.
    expectTcpAccurate("boat-xyzac.ngc", program, 30.0, 1500, 1);
}

TEST(PostprocTcp, IdentityKeepsTcpProgramsByteForByte) {
    const std::string path = test::sharedPath("gcode-corpus/impeller-7bl-xyzac.ngc");
    if (!std::filesystem::exists(path)) GTEST_SKIP() << "no " << path;
    SimFiles st;
    const MachineModel m = readMachineXml(st.machine);
    CorrectOptions o;
    o.tcpOnM = 428;
    o.tcpOffM = 429;
    const std::string program = test::readText(path);
    std::istringstream in(program);
    std::ostringstream out;
    const CorrectSummary s = correctProgram(m, DeviationSet(m), in, out, o);
    EXPECT_TRUE(out.str() == program);
    EXPECT_EQ(s.tcpMoves, s.moves);
    EXPECT_GE(s.tcpMoves, 4400u);
}

// --- Vector programs (Fanuc G43.5 I J K, Sinumerik TRAORI A3= B3= C3=) on the same machine --------------------------
// The vector points from the tip towards the spindle (Fanuc A-79348E p. 9 "tool axis direction"; Sinumerik PGA
// 6FC5398-2BP10 7-20 "the vector points towards the tool adapter"). On this table it is
// v = Rz(-C) Rx(-A) (0, 0, 1) = (sin C sin A, cos C sin A, cos A); A < 0 is the branch used here.
World anglesOf(const Vec3& tipWorld, Vec3 v, double cNear) {
    v.normalize();
    World w{tipWorld.x(), tipWorld.y(), tipWorld.z(), -std::acos(std::clamp(v.z(), -1.0, 1.0)) / kDeg, 0};
    double c = std::atan2(-v.x(), -v.y()) / kDeg;
    c += 360.0 * std::round((cNear - c) / 360.0);
    w.c = c;
    return w;
}

struct VectorBlock {
    Vec3 tip, v;
    int motion = 1;
};

std::vector<VectorBlock> vectorMoves(const std::string& program, bool sinumerik) {
    std::vector<VectorBlock> out;
    std::istringstream in(program);
    std::string s;
    VectorBlock b;
    bool tcp = false;
    while (std::getline(in, s)) {
        if (s.find(sinumerik ? "TRAORI" : "G43.5") != std::string::npos) tcp = true;
        if (!tcp) continue;
        bool any = false, vec = false;
        Vec3 v = Vec3::Zero();
        for (size_t k = 0; k < s.size();) {
            const char c = s[k];
            if (!std::isalpha(static_cast<unsigned char>(c))) {
                ++k;
                continue;
            }
            size_t e = k + 1;
            int idx = -1;
            if (sinumerik && (c == 'A' || c == 'B' || c == 'C') && e + 1 < s.size() && s[e] == '3' && s[e + 1] == '=')
                idx = c - 'A', e += 2;
            else if (!sinumerik && (c == 'I' || c == 'J' || c == 'K'))
                idx = c - 'I';
            size_t used = 0;
            double val = 0;
            try {
                val = std::stod(s.substr(e), &used);
            } catch (...) {
                k = e;
                continue;
            }
            k = e + used;
            if (idx >= 0) v[idx] = val, vec = true;
            if (c == 'X') b.tip.x() = val, any = true;
            if (c == 'Y') b.tip.y() = val, any = true;
            if (c == 'Z') b.tip.z() = val, any = true;
            if (c == 'G' && (val == 0 || val == 1)) b.motion = static_cast<int>(val);
        }
        if (vec) b.v = v.normalized();
        if (any || vec) out.push_back(b);
    }
    return out;
}

std::string vectorProgram(bool sinumerik) {
    std::string p = sinumerik ? "G90 G71\nTRAORI\n" : "G21 G90\nG43.5 H1\n";
    char buf[200];
    for (int k = 0; k <= 40; ++k) {
        const double a = (-30.0 - 12.0 * std::sin(k * 0.08)) * kDeg, c = (10.0 + 1.5 * k) * kDeg;
        const Vec3 v(std::sin(c) * std::sin(a), std::cos(c) * std::sin(a), std::cos(a));
        const double x = -20 + k, y = 5 + 3 * std::sin(k * 0.1), z = 10 - 0.1 * k;
        if (sinumerik)
            std::snprintf(buf, sizeof buf, "G%d X%.4f Y%.4f Z%.4f A3=%.7f B3=%.7f C3=%.7f%s\n", k == 0 ? 0 : 1, x, y, z,
                          v.x(), v.y(), v.z(), k == 1 ? " F300" : "");
        else
            std::snprintf(buf, sizeof buf, "G%d X%.4f Y%.4f Z%.4f I%.7f J%.7f K%.7f%s\n", k == 0 ? 0 : 1, x, y, z, v.x(),
                          v.y(), v.z(), k == 1 ? " F300." : "");
        p += buf;
    }
    return p + (sinumerik ? "TRAFOOF\nM30\n" : "G49\nM30\n");
}

/// The tool tip (at L, the programmed point's tool length) of a vector block through the controller and a machine.
Vec3 vectorTip(const Vec3& tip, const Vec3& v, double& cNear, double L, const Errors* e) {
    const World w = anglesOf(tip, v, cNear);
    cNear = w.c;
    World lc = w;
    lc.z += L;  // LinuxCNC's world carries the tool offset in Z (see ControllerModelMatchesLinuxCncTrtKinematics)
    return machineTip(trtInverse(lc, L), L, e).tip;
}

void expectVectorProgramAccurate(bool sinumerik) {
    SimFiles st;
    const MachineModel m = readMachineXml(st.machine);
    const DeviationSet d = readDeviationCsv(st.deviations, m);
    const double L = 30.0;
    CorrectOptions o;
    o.dialect = sinumerik ? Dialect::Sinumerik : Dialect::Fanuc;
    o.setup.addToolLength(sinumerik ? "30" : "H1=30");
    o.corrector.toleranceMm = 0.5 * kUm;
    const std::string program = vectorProgram(sinumerik);
    std::istringstream in(program);
    std::ostringstream out;
    const CorrectSummary s = correctProgram(m, d, in, out, o);
    EXPECT_EQ(s.passedThrough, 0u) << formatSummary(s) << out.str();
    EXPECT_EQ(s.tcpMoves, 41u) << formatSummary(s);
    const auto nom = vectorMoves(program, sinumerik), act = vectorMoves(out.str(), sinumerik);
    ASSERT_EQ(nom.size(), 41u);
    ASSERT_GE(act.size(), nom.size()) << out.str();
    // Nominal tip path: the programmed points (at L = the controlled length) joined by straight lines.
    auto distance = [&](const Vec3& p) {
        double best = HUGE_VAL;
        for (size_t k = 1; k < nom.size(); ++k) {
            const Vec3 a = nom[k - 1].tip, b = nom[k].tip;
            const double t = std::clamp((p - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
            best = std::min(best, (a + t * (b - a) - p).norm());
        }
        return best;
    };
    const Errors errors;
    double cNear = 0, worstEnd = 0, worstMid = 0, uncorrected = 0;
    for (size_t k = 0; k < act.size(); ++k) {
        worstEnd = std::max(worstEnd, distance(vectorTip(act[k].tip, act[k].v, cNear, L, &errors)));
        if (k > 0 && act[k].motion == 1) {
            // The controller interpolates the tip linearly and turns the vector in the plane of its ends [G].
            double c = cNear;
            const Vec3 mid = vectorTip(0.5 * (act[k - 1].tip + act[k].tip), slerpVector(act[k - 1].v, act[k].v, 0.5), c,
                                       L, &errors);
            worstMid = std::max(worstMid, distance(mid));
        }
    }
    cNear = 0;
    for (const auto& b : nom) uncorrected = std::max(uncorrected, distance(vectorTip(b.tip, b.v, cNear, L, &errors)));
    std::printf("[ tcp      ] %s vector program: end points %.4f um, midpoints %.4f um (uncorrected %.2f um)\n",
                sinumerik ? "Sinumerik A3/B3/C3" : "Fanuc G43.5 IJK", worstEnd / kUm, worstMid / kUm, uncorrected / kUm);
    EXPECT_GT(uncorrected, 10 * kUm);
    EXPECT_LE(worstEnd, 0.5 * kUm);
    EXPECT_LE(worstMid, 0.5 * kUm);
}

TEST(PostprocTcp, FanucG435VectorProgram) { expectVectorProgramAccurate(false); }
TEST(PostprocTcp, SinumerikTraoriVectorProgram) { expectVectorProgramAccurate(true); }

}  // namespace
}  // namespace cnccomp::postproc
