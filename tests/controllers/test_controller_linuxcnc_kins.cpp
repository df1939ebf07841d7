// The generated LinuxCNC kinematics component (controllers/linuxcnc/kins_component.hpp), checked as C: the C part of
// the generated .comp is compiled here with the system gcc against a small shim standing in for LinuxCNC's
// rtapi_math.h / hal.h / kinematics.h (tests/data/linuxcnc_kins_shim/), loaded with dlopen, and its
// kinematicsInverse / kinematicsForward are run on random poses of every sample machine in both modes.
// Oracles: cnccomp's exact forward model (Kinematics) — the erroneous machine at the component's joints must put the
// tool tip where the nominal machine (joint mode) or the TCP world words (tool-tip mode, world frame of
// postproc/tcp_model.hpp, an independent implementation of that convention) put it — and cnccomp's inverse
// (solveToolPose, same objective) for the joints; round trips forward∘inverse. halcompile itself (LinuxCNC 2.9,
// Debian package linuxcnc-uspace-dev) compiles every generated file (--compile, nothing installed).
#include <dlfcn.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>
#include <ctime>
#include <set>
#include <sstream>

#include <gtest/gtest.h>

#include "cnccomp/error.hpp"
#include "cnccomp/inverse_kinematics.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "controllers/linuxcnc/kins_component.hpp"
#include "cnccomp/kinematics_engine.hpp"
#include "postproc/tcp_model.hpp"
#include "test_support.hpp"

namespace cnccomp {
using namespace cnccomp::io;
namespace {

using controllers::linuxcnc::kinematicsComponent;
using controllers::linuxcnc::KinsComponentOptions;

/// EmcPose as LinuxCNC 2.9's emcpos.h lays it out (the shim's copy).
struct CPose {
    double x, y, z, a, b, c, u, v, w;
};

/// The compiled component, loaded.
class LoadedKins {
public:
    using Inverse = int (*)(const CPose*, double*, const unsigned long*, unsigned long*);
    using Forward = int (*)(const double*, CPose*, const unsigned long*, unsigned long*);
    LoadedKins(const std::string& so) {
        handle_ = dlopen(so.c_str(), RTLD_NOW | RTLD_LOCAL);
        if (!handle_) throw std::runtime_error(dlerror());
        inverse = reinterpret_cast<Inverse>(dlsym(handle_, "kinematicsInverse"));
        forward = reinterpret_cast<Forward>(dlsym(handle_, "kinematicsForward"));
        type = reinterpret_cast<int (*)()>(dlsym(handle_, "kinematicsType"));
        kinsSwitch = reinterpret_cast<int (*)(int)>(dlsym(handle_, "kinematicsSwitch"));
        pin = reinterpret_cast<void* (*)(const char*)>(dlsym(handle_, "shim_pin"));
        if (!inverse || !forward || !type || !kinsSwitch || !pin) throw std::runtime_error("symbol missing");
        if (type() != 4) throw std::runtime_error("kinematicsType is not KINEMATICS_BOTH");  // also makes the pins
    }
    ~LoadedKins() {
        if (handle_) dlclose(handle_);
    }
    LoadedKins(const LoadedKins&) = delete;
    LoadedKins& operator=(const LoadedKins&) = delete;
    double& floatPin(const std::string& name) {
        void* p = pin(name.c_str());
        if (!p) throw std::runtime_error("no pin " + name);
        return *static_cast<double*>(p);
    }
    bool bitPin(const std::string& name) {
        void* p = pin(name.c_str());
        if (!p) throw std::runtime_error("no pin " + name);
        return *static_cast<bool*>(p);
    }
    Inverse inverse = nullptr;
    Forward forward = nullptr;
    int (*type)() = nullptr;
    int (*kinsSwitch)(int) = nullptr;
    void* (*pin)(const char*) = nullptr;

private:
    void* handle_ = nullptr;
};

std::string shimDir() { return test::sourcePath("tests/data/linuxcnc_kins_shim"); }

/// The C part of a .comp (after the line ";;").
std::string cPart(const std::string& comp) {
    const auto p = comp.find("\n;;\n");
    if (p == std::string::npos) throw std::runtime_error("no ;; line");
    return comp.substr(p + 4);
}

/// The code-generation flags LinuxCNC 2.9 builds realtime modules with (/usr/share/linuxcnc/Makefile.modinc, uspace:
/// RTFLAGS and EXTRA_CFLAGS): no fast math, and sin/cos not merged into sincos, which the realtime math lacks.
const std::string kRtFlags =
    "-Os -fno-fast-math -fno-unsafe-math-optimizations -fno-builtin-sin -fno-builtin-cos -fno-builtin-sincos "
    "-Wframe-larger-than=2560";

/// Compiles the generated C (and the shim) into a shared object in `dir`; returns its path.
std::string compileComponent(const test::ScratchDir& dir, const std::string& comp) {
    const std::string& opt = kRtFlags;
    test::writeText(dir.file("kins.c"), cPart(comp));
    const std::string so = dir.file("kins.so");
    const auto r = test::runCommand("gcc -std=gnu99 " + opt + " -fPIC -shared -Wall -Wextra -Werror -I" + shimDir() +
                                    " -o " + so + " " + dir.file("kins.c") + " " + shimDir() + "/shim.c -lm 2>&1");
    if (r.exitCode != 0) throw std::runtime_error("gcc failed:\n" + r.out);
    return so;
}

struct Sample {
    const char* machine;
    const char* deviations;
};
// Every sample machine with its deviation (truth) file; component errors of every basis among them.
const Sample kSamples[] = {
    {"multitasking", "multitasking-truth"},
    {"table-table-ac", "table-table-ac-truth"},
    {"controllers-table-table-ac", "controllers-table-table-ac"},
    {"table-table-bc-offsets", "table-table-bc-offsets-truth"},
    {"table-table-bc", "dbb5-table-table-bc-truth"},
    {"tilting-head-b", "tilting-head-b-truth"},
    {"controllers-tilting-head-b", "controllers-tilting-head-b"},
    {"controllers-siemens-components", "controllers-siemens-components"},
    {"controllers-heidenhain-components", "controllers-heidenhain-components"},
    {"controllers-fanuc-pitch", "controllers-fanuc-pitch"},
};

DeviationSet sampleDeviations(const MachineModel& m, const std::string& stem) {
    return readDeviationCsv(test::sourcePath("samples/deviations/" + stem + ".csv"), m);
}

double unitOf(const MachineModel& m, int i) { return m.axisLink(i).kind == AxisKind::Rotary ? kDeg : 1.0; }

/// Controller units (mm, deg from machine zero) of model commands q.
std::vector<double> toJoints(const MachineModel& m, const AxisVector& q) {
    const AxisVector c = m.toController(q);
    std::vector<double> j(m.axisCount());
    for (int i = 0; i < m.axisCount(); ++i) j[i] = c[i] / unitOf(m, i);
    return j;
}
AxisVector fromJoints(const MachineModel& m, const double* j) {
    AxisVector c(m.axisCount());
    for (int i = 0; i < m.axisCount(); ++i) c[i] = j[i] * unitOf(m, i);
    return m.fromController(c);
}

double& slot(CPose& p, const std::string& axis) {
    switch (axis[0]) {
        case 'X': return p.x;
        case 'Y': return p.y;
        case 'Z': return p.z;
        case 'A': return p.a;
        case 'B': return p.b;
        case 'C': return p.c;
        case 'U': return p.u;
        case 'V': return p.v;
        default: return p.w;
    }
}

/// Random model commands inside the travel (rotary axes within ±400° at most, away from the travel ends).
AxisVector randomCommands(const MachineModel& m, std::mt19937& rng) {
    AxisVector q(m.axisCount());
    for (int i = 0; i < m.axisCount(); ++i) {
        const Link& l = m.axisLink(i);
        double lo = l.min, hi = l.max;
        if (l.kind == AxisKind::Rotary) {
            lo = std::max(lo, -400 * kDeg);
            hi = std::min(hi, 400 * kDeg);
        }
        const double margin = 0.02 * (hi - lo);
        q[i] = std::uniform_real_distribution<double>(lo + margin, hi - margin)(rng);
    }
    return q;
}

IkOptions referenceOptions(const KinsComponentOptions& o) {
    IkOptions ik = controllers::linuxcnc::kinsSolverOptions(o);
    ik.tolerance = 1e-12;
    return ik;
}

struct Figures {
    double jointDiff = 0, tipErr = 0, roundTrip = 0;
};

void checkMachine(const Sample& s, int poses, Figures& fig) {
    SCOPED_TRACE(s.machine);
    const MachineModel& m = test::sampleMachine(s.machine);
    const DeviationSet d = sampleDeviations(m, s.deviations);
    const KinsComponentOptions o;
    const std::string comp = kinematicsComponent(m, d, o);
    test::ScratchDir dir(std::string("kins-") + s.machine);
    LoadedKins k(compileComponent(dir, comp));
    const Kinematics nominal(m), real(m, d);
    const KinematicsModel compiledNominal(m, nullptr);
    KinematicsData kd(compiledNominal);
    const postproc::TcpModel tcp(compiledNominal, kd);
    const int n = m.axisCount();
    std::mt19937 rng(20261126);
    const IkOptions ik = referenceOptions(o);
    for (int mode : {0, 1}) {
        ASSERT_EQ(k.kinsSwitch(mode), 0);
        EXPECT_EQ(k.bitPin("kinstype.is-1"), mode == 1);
        for (int pose = 0; pose < poses; ++pose) {
            SCOPED_TRACE(testing::Message() << "mode " << mode << " pose " << pose);
            const AxisVector q = randomCommands(m, rng);
            const double L = std::uniform_real_distribution<double>(0, 150)(rng);
            k.floatPin("cnccomp_kins.tool-offset") = L;
            const Vec3 tipInTool = nominal.toolPoint(L);
            const std::vector<double> c = toJoints(m, q);
            CPose world{};
            ToolPose target;
            if (mode == 0) {
                // Joint mode: the words are the nominal commands.
                for (int i = 0; i < n; ++i) slot(world, m.axisNames[i]) = c[i];
                target = toolPose(nominal, q, tipInTool);
            } else {
                // Tool-tip mode: the TCP words of these nominal joints (postproc's TcpModel: world X Y Z of the tip
                // at length L, rotary words = the angles).
                AxisVector cc(n), p;
                for (int i = 0; i < n; ++i) cc[i] = c[i] * unitOf(m, i);
                tcp.toProgram(kd, cc, L, p);
                p[m.requireAxis("Z")] += L;  // G43: LinuxCNC adds the tool length to the Z word (emccanon.cc)
                for (int i = 0; i < n; ++i) slot(world, m.axisNames[i]) = p[i] / unitOf(m, i);
                target = toolPose(nominal, q, tipInTool);  // the nominal machine at those joints
            }
            std::vector<double> joints = c;  // LinuxCNC passes the current joints: here the nominal ones
            ASSERT_EQ(k.inverse(&world, joints.data(), nullptr, nullptr), 0);
            EXPECT_FALSE(k.bitPin("cnccomp_kins.fail"));
            const AxisVector qj = fromJoints(m, joints.data());
            // The erroneous machine at the component's joints puts the tip where the nominal one is (1 nm).
            const ToolPose got = toolPose(real, qj, tipInTool);
            const double tipErr = (got.tip - target.tip).norm();
            EXPECT_LE(tipErr, 1e-6);
            fig.tipErr = std::max(fig.tipErr, tipErr);
            // cnccomp's inverse on the same objective gives the same joints (1e-9 mm / deg).
            const IkResult ref = solveToolPose(real, target, tipInTool, q, ik);
            const std::vector<double> refJ = toJoints(m, ref.q);
            for (int i = 0; i < n; ++i) {
                EXPECT_NEAR(joints[i], refJ[i], 1e-9) << m.axisNames[i];
                fig.jointDiff = std::max(fig.jointDiff, std::abs(joints[i] - refJ[i]));
            }
            // forward∘inverse = identity.
            CPose back{};
            ASSERT_EQ(k.forward(joints.data(), &back, nullptr, nullptr), 0);
            EXPECT_FALSE(k.bitPin("cnccomp_kins.fail"));
            for (int i = 0; i < n; ++i) {
                const double diff = std::abs(slot(back, m.axisNames[i]) - slot(world, m.axisNames[i]));
                EXPECT_LE(diff, 1e-9) << m.axisNames[i];
                fig.roundTrip = std::max(fig.roundTrip, diff);
            }
            // inverse∘forward from other joints near these (the forward is the inverse's inverse).
            std::vector<double> j2 = joints;
            for (int i = 0; i < n; ++i) j2[i] += std::uniform_real_distribution<double>(-0.5, 0.5)(rng);
            CPose w2{};
            ASSERT_EQ(k.forward(j2.data(), &w2, nullptr, nullptr), 0);
            std::vector<double> j3 = joints;
            ASSERT_EQ(k.inverse(&w2, j3.data(), nullptr, nullptr), 0);
            for (int i = 0; i < n; ++i) EXPECT_NEAR(j3[i], j2[i], 1e-9) << m.axisNames[i];
        }
    }
}

TEST(LinuxcncKinsComponent, JointAndToolTipModesMatchTheExactModelOnEverySample) {
    for (const Sample& s : kSamples) {
        Figures fig;
        checkMachine(s, 20, fig);
        std::printf("%-36s joints vs cnccomp %.2e mm|deg, tip %.2e mm, forward(inverse) %.2e\n", s.machine,
                    fig.jointDiff, fig.tipErr, fig.roundTrip);
    }
}


// The HAL pins carry the model: with every deviation pin at 0 the component is the nominal machine, whose joint-mode
// inverse is the identity; a NaN word keeps the joints and sets `fail`; symbols the C needs are math and HAL only.
TEST(LinuxcncKinsComponent, PinsCarryTheDeviationsAndFailureKeepsTheJoints) {
    const MachineModel& m = test::sampleMachine("table-table-bc-offsets");
    const DeviationSet d = sampleDeviations(m, "table-table-bc-offsets-truth");
    const std::string comp = kinematicsComponent(m, d, {});
    test::ScratchDir dir("kins-pins");
    LoadedKins k(compileComponent(dir, comp));
    const int n = m.axisCount();
    std::mt19937 rng(7);
    const AxisVector q = randomCommands(m, rng);
    const std::vector<double> c = toJoints(m, q);
    CPose world{};
    for (int i = 0; i < n; ++i) slot(world, m.axisNames[i]) = c[i];
    std::vector<double> j = c;
    ASSERT_EQ(k.inverse(&world, j.data(), nullptr, nullptr), 0);
    double moved = 0;
    for (int i = 0; i < n; ++i) moved = std::max(moved, std::abs(j[i] - c[i]));
    EXPECT_GT(moved, 1e-3);  // the identified deviations move the joints
    // Each pin holds its deviation's link value (mm, rad).
    int pins = 0;
    for (int di = 0; di < static_cast<int>(m.deviations.size()); ++di)
        for (int kk = 0; kk < m.deviations[di].size(); ++kk, ++pins) {
            double& v = k.floatPin("cnccomp_kins." + controllers::linuxcnc::kinsDeviationPin(m, di, kk));
            EXPECT_EQ(v, d.values[m.deviations[di].offset + kk]);
            v = 0.0;
        }
    EXPECT_EQ(pins, m.parameterCount());
    j = c;
    ASSERT_EQ(k.inverse(&world, j.data(), nullptr, nullptr), 0);
    for (int i = 0; i < n; ++i) EXPECT_NEAR(j[i], c[i], 1e-10) << m.axisNames[i];
    // Not solvable: the joints stay, fail is set, the call fails (motion stops with "kinematicsInverse failed").
    world.x = std::nan("");
    std::vector<double> kept = c;
    EXPECT_EQ(k.inverse(&world, kept.data(), nullptr, nullptr), -1);
    EXPECT_TRUE(k.bitPin("cnccomp_kins.fail"));
    for (int i = 0; i < n; ++i) EXPECT_EQ(kept[i], c[i]);
    // Realtime: the component's object needs nothing of the C library beyond math, and the HAL / RTAPI calls.
    const auto nm = test::runCommand("gcc -std=gnu99 " + kRtFlags + " -c -I" + shimDir() + " -o " + dir.file("kins.o") + " " +
                                     dir.file("kins.c") + " && nm -u " + dir.file("kins.o"));
    ASSERT_EQ(nm.exitCode, 0) << nm.out;
    std::istringstream names(nm.out);
    std::string type, name;
    const std::set<std::string> allowed = {"cos", "sin", "sqrt", "fmod", "hal_pin_float_newf", "hal_pin_bit_newf",
                                           "hal_pin_s32_newf", "hal_malloc", "hal_set_unready", "hal_ready",
                                           "rtapi_print_msg"};
    while (names >> type >> name) EXPECT_TRUE(allowed.count(name)) << "the component calls " << name;
}

// Joint mode on a 5-axis machine matches the tool axis as well as the tip away from singular poses (outside the
// component's singular zone the pull is off), so there the joints do not depend on the tool length (tool-offset);
// inside the zone the axis keeps part of its error and the tip is met at the tool-offset length. On the 4-axis head
// (X Y Z B) the axis cannot be matched and the tip at tool-offset is met.
TEST(LinuxcncKinsComponent, JointModeIndependentOfToolLengthWhereTheAxisIsMatched) {
    for (const Sample& s : {kSamples[0], kSamples[5]}) {
        SCOPED_TRACE(s.machine);
        const MachineModel& m = test::sampleMachine(s.machine);
        const DeviationSet d = sampleDeviations(m, s.deviations);
        test::ScratchDir dir(std::string("kins-length-") + s.machine);
        LoadedKins k(compileComponent(dir, kinematicsComponent(m, d, {})));
        const Kinematics nominal(m), real(m, d);
        std::mt19937 rng(11);
        double spread = 0, spreadInZone = 0;
        int outside = 0;
        for (int pose = 0; pose < 10; ++pose) {
            const AxisVector q = randomCommands(m, rng);
            PoseJacobian Jq;
            toolPoseJacobian(real, q, nominal.toolPoint(0), Jq);
            const bool inZone = rotarySingularValue(m, Jq) < KinsComponentOptions{}.singularZone * 1.05;
            outside += !inZone;
            const std::vector<double> c = toJoints(m, q);
            CPose world{};
            for (int i = 0; i < m.axisCount(); ++i) slot(world, m.axisNames[i]) = c[i];
            std::vector<std::vector<double>> byLength;
            for (double L : {0.0, 150.0}) {
                k.floatPin("cnccomp_kins.tool-offset") = L;
                std::vector<double> j = c;
                ASSERT_EQ(k.inverse(&world, j.data(), nullptr, nullptr), 0);
                const Vec3 tip = nominal.toolPoint(L);
                EXPECT_LE((real.toolPointInWorkpiece(fromJoints(m, j.data()), tip) -
                           nominal.toolPointInWorkpiece(q, tip)).norm(),
                          1e-6);
                byLength.push_back(j);
            }
            for (int i = 0; i < m.axisCount(); ++i)
                (inZone ? spreadInZone : spread) = std::max(inZone ? spreadInZone : spread, std::abs(byLength[0][i] - byLength[1][i]));
        }
        if (m.axisCount() == 5) {
            EXPECT_GE(outside, 5);
            EXPECT_LE(spread, 1e-8);
            EXPECT_LE(spreadInZone, 150 * 1e-4);  // at most the tool length times the tool-axis error (< 20 arcsec)
        } else {
            EXPECT_GT(spread, 1e-6);  // the head's tilt out of the B plane: the tip then depends on the length
        }
    }
}

// The multi-tasking machine at B = 0 and ±180° (tool axis parallel to C: C cannot turn the axis), next to it, inside
// the singular zone and at its edge (σ = sin B = 0.1 at 5.74°): the tip is still met, C stays next to its command (the
// singular-pose policy's damping), nothing fails, forward∘inverse is the identity, and the joints are cnccomp's inverse
// with the same policy (solveToolPose with kinsSolverOptions: the C's Jacobi eigen-decomposition and damping against
// Eigen's) to 1e-9 mm / deg.
TEST(LinuxcncKinsComponent, SingularPoseOfTheMultitaskingMachine) {
    const MachineModel& m = test::sampleMachine("multitasking");
    const DeviationSet d = sampleDeviations(m, "multitasking-truth");
    test::ScratchDir dir("kins-singular");
    LoadedKins k(compileComponent(dir, kinematicsComponent(m, d, {})));
    const Kinematics nominal(m), real(m, d);
    const IkOptions ik = referenceOptions({});
    const int b = m.requireAxis("B"), c = m.requireAxis("C");
    double worst = 0;
    for (int mode : {0, 1}) {
        ASSERT_EQ(k.kinsSwitch(mode), 0);
        for (double bDeg : {0.0, 1e-4, -0.01, 0.5, 2.0, -4.0, 5.7, 5.75, 8.0, 180.0, -179.99, 176.0}) {
            SCOPED_TRACE(testing::Message() << "mode " << mode << " B " << bDeg);
            AxisVector q = AxisVector::Zero(m.axisCount());
            q[m.requireAxis("X")] = 120;
            q[m.requireAxis("Y")] = -15;
            q[m.requireAxis("Z")] = 300;
            q[b] = bDeg * kDeg;
            q[c] = 33 * kDeg;
            const double L = 60;
            k.floatPin("cnccomp_kins.tool-offset") = L;
            const std::vector<double> cj = toJoints(m, q);
            CPose world{};
            if (mode == 0) {
                for (int i = 0; i < m.axisCount(); ++i) slot(world, m.axisNames[i]) = cj[i];
            } else {
                const KinematicsModel compiledNominal(m, nullptr);
                KinematicsData kd(compiledNominal);
                const postproc::TcpModel tcp(compiledNominal, kd);
                AxisVector cc(m.axisCount()), p;
                for (int i = 0; i < m.axisCount(); ++i) cc[i] = cj[i] * unitOf(m, i);
                tcp.toProgram(kd, cc, L, p);
                p[m.requireAxis("Z")] += L;  // G43: LinuxCNC adds the tool length to the Z word (emccanon.cc)
                for (int i = 0; i < m.axisCount(); ++i) slot(world, m.axisNames[i]) = p[i] / unitOf(m, i);
            }
            std::vector<double> j = cj;
            ASSERT_EQ(k.inverse(&world, j.data(), nullptr, nullptr), 0);
            EXPECT_FALSE(k.bitPin("cnccomp_kins.fail"));
            const Vec3 tip = nominal.toolPoint(L);
            EXPECT_LE((real.toolPointInWorkpiece(fromJoints(m, j.data()), tip) - nominal.toolPointInWorkpiece(q, tip))
                          .norm(),
                      1e-6);
            EXPECT_NEAR(j[c], cj[c], 0.1);  // C is not swung round to chase a tilt
            const std::vector<double> ref = toJoints(m, solveToolPose(real, toolPose(nominal, q, tip), tip, q, ik).q);
            for (int i = 0; i < m.axisCount(); ++i) {
                EXPECT_NEAR(j[i], ref[i], 1e-9) << m.axisNames[i];
                worst = std::max(worst, std::abs(j[i] - ref[i]));
            }
            CPose back{};
            ASSERT_EQ(k.forward(j.data(), &back, nullptr, nullptr), 0);
            for (int i = 0; i < m.axisCount(); ++i)
                EXPECT_NEAR(slot(back, m.axisNames[i]), slot(world, m.axisNames[i]), 1e-9) << m.axisNames[i];
        }
    }
    std::printf("multitasking at and near its singular poses: joints vs cnccomp %.2e mm|deg\n", worst);
}

// Three rotary joints (the multi-tasking machine with an A table under C, X Y Z A B C): the rotary block G = JaᵀJa is
// 3 × 3 of rank ≤ 2 (a unit tool axis has two degrees of freedom), so one direction always has σ = 0 and is damped,
// and the C decomposes G by Jacobi sweeps (not the one rotation of two joints). Its joints are cnccomp's inverse with
// the same policy (Eigen's closed-form 3 × 3 decomposition) to 1e-9 mm / deg, at random poses and with the tilting
// axes at 0; the tip is met within 1 nm. No sample machine has three rotary axes; this one is made here.
TEST(LinuxcncKinsComponent, ThreeRotaryJointsMatchCnccompsInverse) {
    test::ScratchDir dir("kins-three-rotary");
    std::string xml = test::readText(test::sourcePath("samples/machines/multitasking.xml"));
    const std::string cAxis = "<axis name=\"C\" type=\"rotary\"";
    const auto at = xml.find(cAxis);
    ASSERT_NE(at, std::string::npos);
    xml.insert(at, "<axis name=\"A\" type=\"rotary\" direction=\"1 0 0\" min=\"-120\" max=\"120\"/>\n    ");
    test::writeText(dir.file("m3.xml"), xml);
    const MachineModel m = readMachineXml(dir.file("m3.xml"));
    ASSERT_EQ(m.axisCount(), 6);
    DeviationSet d(m);  // location errors of the tool head, the slides and the C axis (µm, arcsec)
    d.set("aBT", 6.5 * kArcsec);
    d.set("bXB", -8.0 * kArcsec);
    d.set("dxBT", 0.012);
    d.set("gXY", 4.0 * kArcsec);
    d.set("aCZ", 3.0 * kArcsec);
    d.set("dxCZ", -0.009);
    LoadedKins k(compileComponent(dir, kinematicsComponent(m, d, {})));
    const Kinematics nominal(m), real(m, d);
    const IkOptions ik = referenceOptions({});
    const int n = m.axisCount();
    std::mt19937 rng(3);
    double worst = 0, worstTip = 0;
    for (int mode : {0, 1}) {
        ASSERT_EQ(k.kinsSwitch(mode), 0);
        for (int pose = 0; pose < 30; ++pose) {
            SCOPED_TRACE(testing::Message() << "mode " << mode << " pose " << pose);
            AxisVector q = randomCommands(m, rng);
            if (pose % 3 == 0)
                for (int i = 0; i < n; ++i)
                    if (m.axisLink(i).kind == AxisKind::Rotary && !m.axisLink(i).modulo) q[i] = 0;
            const double L = 50.0 * (pose % 3);
            k.floatPin("cnccomp_kins.tool-offset") = L;
            const Vec3 tip = nominal.toolPoint(L);
            const std::vector<double> cj = toJoints(m, q);
            CPose world{};
            if (mode == 0) {
                for (int i = 0; i < n; ++i) slot(world, m.axisNames[i]) = cj[i];
            } else {
                const KinematicsModel compiledNominal(m, nullptr);
                KinematicsData kd(compiledNominal);
                const postproc::TcpModel tcp(compiledNominal, kd);
                AxisVector cc(n), p;
                for (int i = 0; i < n; ++i) cc[i] = cj[i] * unitOf(m, i);
                tcp.toProgram(kd, cc, L, p);
                p[m.requireAxis("Z")] += L;  // G43: LinuxCNC adds the tool length to the Z word (emccanon.cc)
                for (int i = 0; i < n; ++i) slot(world, m.axisNames[i]) = p[i] / unitOf(m, i);
            }
            std::vector<double> j = cj;
            ASSERT_EQ(k.inverse(&world, j.data(), nullptr, nullptr), 0);
            EXPECT_FALSE(k.bitPin("cnccomp_kins.fail"));
            const double tipErr =
                (real.toolPointInWorkpiece(fromJoints(m, j.data()), tip) - nominal.toolPointInWorkpiece(q, tip)).norm();
            EXPECT_LE(tipErr, 1e-6);
            worstTip = std::max(worstTip, tipErr);
            const std::vector<double> ref = toJoints(m, solveToolPose(real, toolPose(nominal, q, tip), tip, q, ik).q);
            for (int i = 0; i < n; ++i) {
                EXPECT_NEAR(j[i], ref[i], 1e-9) << m.axisNames[i];
                worst = std::max(worst, std::abs(j[i] - ref[i]));
            }
        }
    }
    std::printf("three rotary joints: joints vs cnccomp %.2e mm|deg, tip %.2e mm\n", worst, worstTip);
}

// Jumps: each pose starts from the joints of the previous, unrelated one (as after a switch of kinstype or a long
// rapid): 100 poses per mode on every sample, all solved, tip within 1 nm.
TEST(LinuxcncKinsComponent, SolvesFromFarAwayJoints) {
    for (const Sample& s : kSamples) {
        SCOPED_TRACE(s.machine);
        const MachineModel& m = test::sampleMachine(s.machine);
        const DeviationSet d = sampleDeviations(m, s.deviations);
        test::ScratchDir dir(std::string("kins-jumps-") + s.machine);
        LoadedKins k(compileComponent(dir, kinematicsComponent(m, d, {})));
        const Kinematics nominal(m), real(m, d);
        const KinematicsModel compiledNominal(m, nullptr);
        KinematicsData kd(compiledNominal);
        const postproc::TcpModel tcp(compiledNominal, kd);
        const int n = m.axisCount();
        std::mt19937 rng(99);
        std::vector<double> joints(n, 0.0);
        int failures = 0;
        double worst = 0;
        for (int mode : {0, 1}) {
            ASSERT_EQ(k.kinsSwitch(mode), 0);
            for (int pose = 0; pose < 100; ++pose) {
                AxisVector q = randomCommands(m, rng);
                if (pose % 4 == 0)  // tilting axes at 0: singular poses (tool axis parallel to C)
                    for (int i = 0; i < n; ++i)
                        if (m.axisLink(i).kind == AxisKind::Rotary && !m.axisLink(i).modulo) q[i] = 0;
                const double L = 100.0 * (pose % 3);
                k.floatPin("cnccomp_kins.tool-offset") = L;
                const std::vector<double> c = toJoints(m, q);
                CPose world{};
                AxisVector cc(n), p;
                for (int i = 0; i < n; ++i) cc[i] = c[i] * unitOf(m, i);
                if (mode == 0) {
                    p = cc;
                } else {
                    tcp.toProgram(kd, cc, L, p);
                    p[m.requireAxis("Z")] += L;  // G43: LinuxCNC adds the tool length to the Z word (emccanon.cc)
                }
                for (int i = 0; i < n; ++i) slot(world, m.axisNames[i]) = p[i] / unitOf(m, i);
                if (k.inverse(&world, joints.data(), nullptr, nullptr) != 0) {
                    ++failures;
                    continue;
                }
                const Vec3 tip = nominal.toolPoint(L);
                worst = std::max(worst, (real.toolPointInWorkpiece(fromJoints(m, joints.data()), tip) -
                                         nominal.toolPointInWorkpiece(q, tip))
                                            .norm());
            }
        }
        EXPECT_EQ(failures, 0);
        EXPECT_LE(worst, 1e-6);
    }
}

// The case that found it: tool-tip mode on the B/C table with offsets, B = 0 and the joints far from the solution.
TEST(LinuxcncKinsComponent, ScaleFreePivotsAtTheSingularity) {
    const MachineModel& m = test::sampleMachine("table-table-bc-offsets");
    const DeviationSet d = sampleDeviations(m, "table-table-bc-offsets-truth");
    test::ScratchDir dir("kins-pivot");
    LoadedKins k(compileComponent(dir, kinematicsComponent(m, d, {})));
    ASSERT_EQ(m.axisNames, (std::vector<std::string>{"B", "C", "X", "Y", "Z"}));
    ASSERT_EQ(k.kinsSwitch(1), 0);
    k.floatPin("cnccomp_kins.tool-offset") = 0;
    CPose world{};
    world.x = -135;
    world.y = 60;
    world.z = 236;
    world.b = 0;
    world.c = 198;
    std::vector<double> joints = {-74.0033, 163.019, -54.0024, 261.007, -32.9954};
    ASSERT_EQ(k.inverse(&world, joints.data(), nullptr, nullptr), 0);
    EXPECT_FALSE(k.bitPin("cnccomp_kins.fail"));
    EXPECT_LE(k.floatPin("cnccomp_kins.residual"), 1e-9);
    CPose back{};
    ASSERT_EQ(k.forward(joints.data(), &back, nullptr, nullptr), 0);
    EXPECT_NEAR(back.x, world.x, 1e-9);
    EXPECT_NEAR(back.y, world.y, 1e-9);
    EXPECT_NEAR(back.z, world.z, 1e-9);
    EXPECT_NEAR(back.c, world.c, 1e-9);
}

TEST(LinuxcncKinsComponent, RefusesWhatItCannotDescribe) {
    const MachineModel& m = test::sampleMachine("multitasking");
    const DeviationSet d(m);
    KinsComponentOptions o;
    o.name = "Bad-Name";
    EXPECT_THROW(kinematicsComponent(m, d, o), ModelError);
    MachineModel renamed = m;
    renamed.axisNames[0] = "Q";
    EXPECT_THROW(kinematicsComponent(renamed, DeviationSet(renamed), {}), ModelError);
}

// halcompile (LinuxCNC 2.9, linuxcnc-uspace-dev) compiles the generated file of every sample machine: --compile
// builds the realtime module in the current folder (a scratch folder here) and installs nothing.
TEST(LinuxcncKinsComponent, HalcompileCompilesEverySample) {
    if (!std::filesystem::exists("/usr/bin/halcompile"))
        GTEST_SKIP() << "halcompile not found (Debian package linuxcnc-uspace-dev, tools/deps.sh)";
    for (const Sample& s : kSamples) {
        SCOPED_TRACE(s.machine);
        const MachineModel& m = test::sampleMachine(s.machine);
        const std::string comp = kinematicsComponent(m, sampleDeviations(m, s.deviations), {});
        test::ScratchDir dir(std::string("halcompile-") + s.machine);
        test::writeText(dir.file("cnccomp_kins.comp"), comp);
        const auto r = test::runCommand("cd " + dir.path.string() + " && halcompile --compile cnccomp_kins.comp 2>&1");
        EXPECT_EQ(r.exitCode, 0) << r.out;
        EXPECT_TRUE(std::filesystem::exists(dir.file("cnccomp_kins.so"))) << r.out;
        // The module defines the kinematics entry points motion looks up.
        const auto sym = test::runCommand("nm -D --defined-only " + dir.file("cnccomp_kins.so"));
        for (const char* f : {"kinematicsForward", "kinematicsInverse", "kinematicsType", "kinematicsSwitchable",
                              "kinematicsSwitch"})
            EXPECT_NE(sym.out.find(f), std::string::npos) << f << "\n" << sym.out;
    }
}

// Cost per call: 1e5 inverse calls of the C compiled with LinuxCNC 2.9's realtime flags (Makefile.modinc: -Os,
// -fno-fast-math, no builtin sin/cos), joint mode and tool-tip mode, on the multi-tasking and A/C samples.
TEST(LinuxcncKinsComponent, InverseCostPerCall) {
    for (const Sample& s : {kSamples[0], kSamples[2]}) {
        const MachineModel& m = test::sampleMachine(s.machine);
        const std::string comp = kinematicsComponent(m, sampleDeviations(m, s.deviations), {});
        test::ScratchDir dir(std::string("kins-cost-") + s.machine);
        LoadedKins k(compileComponent(dir, comp));
        const int n = m.axisCount();
        std::mt19937 rng(3);
        // A path: 1e5 servo periods along a line between two random poses (warm start from the previous joints).
        const AxisVector a = randomCommands(m, rng), b = randomCommands(m, rng);
        k.floatPin("cnccomp_kins.tool-offset") = 80.0;
        for (int mode : {0, 1}) {
            ASSERT_EQ(k.kinsSwitch(mode), 0);
            const int calls = 100000;
            std::vector<CPose> words(calls);
            const KinematicsModel compiledNominal(m, nullptr);
            KinematicsData kd(compiledNominal);
            const postproc::TcpModel tcp(compiledNominal, kd);
            for (int t = 0; t < calls; ++t) {
                const AxisVector q = a + (b - a) * (double(t) / calls);
                const std::vector<double> c = toJoints(m, q);
                if (mode == 0) {
                    for (int i = 0; i < n; ++i) slot(words[t], m.axisNames[i]) = c[i];
                } else {
                    AxisVector cc(n), p;
                    for (int i = 0; i < n; ++i) cc[i] = c[i] * unitOf(m, i);
                    tcp.toProgram(kd, cc, 80.0, p);
                    p[m.requireAxis("Z")] += 80.0;  // G43: LinuxCNC adds the tool length to the Z word (emccanon.cc)
                    for (int i = 0; i < n; ++i) slot(words[t], m.axisNames[i]) = p[i] / unitOf(m, i);
                }
            }
            std::vector<double> j = toJoints(m, a);
            int failures = 0;
            long iterations = 0;
            // CPU time of this thread: the figure a servo thread would see on its own core (wall time on a loaded
            // test machine counts the other processes too; it is printed beside it).
            timespec c0{}, c1{};
            clock_gettime(CLOCK_THREAD_CPUTIME_ID, &c0);
            const auto t0 = std::chrono::steady_clock::now();
            for (int t = 0; t < calls; ++t) {
                failures += k.inverse(&words[t], j.data(), nullptr, nullptr) != 0;
                iterations += *static_cast<int32_t*>(k.pin("cnccomp_kins.iterations"));
            }
            const double wall =
                std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - t0).count() / calls;
            clock_gettime(CLOCK_THREAD_CPUTIME_ID, &c1);
            const double ns = ((c1.tv_sec - c0.tv_sec) * 1e9 + (c1.tv_nsec - c0.tv_nsec)) / calls;
            EXPECT_EQ(failures, 0);
            std::printf("%-28s mode %d: %.0f ns CPU per inverse call (%.2f %% of a 1 ms servo period, %.1f %% of "
                        "50 us; wall %.0f ns), %.2f Gauss-Newton iterations per call\n",
                        s.machine, mode, ns, ns / 1e4, ns / 500, wall, double(iterations) / calls);
            testing::Test::RecordProperty(std::string(s.machine) + "-mode" + std::to_string(mode) + "-ns",
                                          std::to_string(ns));
            EXPECT_LT(ns, 50000.0);  // far below a 1 ms servo period even on a loaded machine
        }
    }
}

}  // namespace
}  // namespace cnccomp
