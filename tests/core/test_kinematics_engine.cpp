// The kinematics engine (src/cnccomp/kinematics_engine.hpp). Two kinds of check:
// - Arithmetic::Fast (folded constant transforms, affine chains evaluated without walking them, rotations from the last
//   angle by angle addition, two cached evaluations per chain in the caller's workspace; toolPoseOnce with the
//   workpiece chain inverted onto the tool point, toolTipOnce, toolInBase, workpiecePointToBase, angles taken from
//   the nominal model's workspace) against cnccomp::Kinematics / toolPoseJacobian, the same model
//   walked link by link without folding, caches or angle addition: every machine in samples/machines (location and
//   component errors), and an inclined rotary axis (a 45° head, the general rotation path), to 1e-12 mm and 1e-13 rad.
//   Sequences of nearby and far poses exercise every cache path.
// - The exact walk itself (cnccomp::Kinematics, and Arithmetic::AsExactModel with its workspace) against ReferenceChain,
//   an independent transcription of the model's equations, to the bit.
// - The walks' scalar arithmetic (cnccomp/xyz.hpp) against the Eigen expressions it stands for, to the bit.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <filesystem>
#include <random>

#include "cnccomp/error.hpp"
#include "cnccomp/inverse_kinematics.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "cnccomp/kinematics_engine.hpp"
#include "cnccomp/xyz.hpp"
#include "test_support.hpp"

namespace cnccomp {
using namespace cnccomp::io;
namespace {

/// A head whose B axis is inclined 45° in the Y-Z plane (as on a nutating head), with location errors on it.
constexpr const char* kInclinedHead = R"xml(<?xml version="1.0" encoding="UTF-8"?>
<machine name="inclined-head" description="test: C table, X Y Z slides, B head inclined 45 deg">
  <workpiece>
    <axis name="C" type="rotary" direction="0 0 1" min="-3600" max="3600"/>
  </workpiece>
  <tool direction="0 0 -1">
    <axis name="X" type="linear" direction="1 0 0" min="-500" max="500"/>
    <axis name="Y" type="linear" direction="0 1 0" min="-500" max="500"/>
    <axis name="Z" type="linear" direction="0 0 1" min="-500" max="500"/>
    <axis name="B" type="rotary" direction="0 0.70710678118654752 0.70710678118654752" min="-180" max="180" offset="0 0 150"/>
    <fixed name="S" offset="0 0 -150"/>
  </tool>
  <deviations>
    <location name="EX0B" link="B" component="x"/>
    <location name="EA0B" link="B" component="a"/>
    <location name="EC0B" link="B" component="c"/>
    <location name="EX0C" link="C" component="x"/>
    <location name="EB0C" link="C" component="b"/>
    <location name="EZ0S" link="S" component="z"/>
  </deviations>
</machine>
)xml";

DeviationSet randomSet(const MachineModel& m, std::mt19937_64& rng) {
    std::uniform_real_distribution<double> u(-1, 1);
    DeviationSet d(m);
    for (int i = 0; i < d.values.size(); ++i) d.values[i] = u(rng) * 1e-3;  // link values: mm, rad, coefficients
    return d;
}

void compare(const MachineModel& m, const DeviationSet& d, const std::string& name) {
    const Kinematics ref(m, d);
    const KinematicsModel k(m, &d);
    KinematicsData data = k.createData();
    const KinematicsModel nominal(m, nullptr);  // evaluated first at the same commands, its angles then taken
    KinematicsData nominalData = nominal.createData();
    std::mt19937_64 rng(11), rngPoint(13);  // (the poses' sequence as before the workpiece points were added)
    std::uniform_real_distribution<double> u(-1, 1);
    AxisVector q(m.axisCount());
    for (int i = 0; i < m.axisCount(); ++i) q[i] = m.axisLink(i).kind == AxisKind::Rotary ? u(rng) : 100 * u(rng);
    double worstTip = 0, worstAxis = 0, worstJ = 0, worstBase = 0, worstTaken = 0;
    for (int trial = 0; trial < 250; ++trial) {
        // Mostly small steps (Newton steps, neighbouring blocks: angle addition), sometimes a jump, sometimes a
        // pose seen two evaluations ago (the second cache entry).
        AxisVector prev = q;
        const int kind = trial % 7;
        for (int i = 0; i < m.axisCount(); ++i) {
            const bool rotary = m.axisLink(i).kind == AxisKind::Rotary;
            const double step = kind == 0 ? (rotary ? 2.0 : 200.0) : kind < 4 ? (rotary ? 0.04 : 5.0) : (rotary ? 1e-6 : 1e-4);
            q[i] += step * u(rng);
            if (!rotary && std::fabs(q[i]) > 500.0) q[i] = std::copysign(1000.0, q[i]) - q[i];  // reflected into ±500 mm
        }
        if (kind == 5) std::swap(q, prev);
        for (double L : {0.0, 120.0}) {
            Vec3 tip, axis;
            k.toolPose(data, q, L, tip, axis);
            const ToolPose r = toolPose(ref, q, ref.toolPoint(L));
            worstTip = std::max(worstTip, (tip - r.tip).norm());
            worstAxis = std::max(worstAxis, (axis - r.axis).norm());
            PoseJacobian J, Jr;
            Vec3 t2, a2;
            k.jacobian(data, q, L, J, t2, a2);
            toolPoseJacobian(ref, q, ref.toolPoint(L), Jr);
            worstJ = std::max(worstJ, (J - Jr).cwiseAbs().maxCoeff());
            EXPECT_LT((t2 - r.tip).norm(), 1e-9) << name;
            // The same pose with the workpiece chain inverted onto the tool point (no frame built).
            Vec3 tipOnce, axisOnce;
            k.toolPoseOnce(data, q, L, tipOnce, axisOnce);
            worstTip = std::max(worstTip, (tipOnce - r.tip).norm());
            worstAxis = std::max(worstAxis, (axisOnce - r.axis).norm());
            worstAxis = std::max(worstAxis, (k.toolAxisOnce(data, q) - r.axis).norm());
            // The tool point alone: toolPoseOnce's to the bit.
            EXPECT_EQ(k.toolTipOnce(data, q, L), tipOnce) << name;
            // In the bed: the tool frame's point and direction; a workpiece point through the workpiece frame.
            Vec3 tipB, axisB;
            k.toolInBase(data, q, L, tipB, axisB);
            const Frame bt = k.baseToTool(data, q), bw = k.baseToWorkpiece(data, q);
            worstBase = std::max(worstBase, (tipB - (bt.t + L * (bt.R * m.toolDirection))).norm());
            worstAxis = std::max(worstAxis, (axisB - bt.R * m.toolDirection).norm());
            const Vec3 p(100 * u(rngPoint), 100 * u(rngPoint), 100 * u(rngPoint));
            worstBase = std::max(worstBase, (k.workpiecePointToBase(data, q, p) - (bw.R * p + bw.t)).norm());
            worstBase = std::max(worstBase, (k.workpiecePointToBase(data, q, r.tip) - tipB).norm());
            // The nominal machine at the same commands first, its cosines and sines taken: the erroneous pose still.
            Vec3 tipN, axisN;
            nominal.toolPoseOnce(nominalData, q, L, tipN, axisN);
            k.takeAngles(data, nominal, nominalData);
            worstTaken = std::max(worstTaken, (k.toolTipOnce(data, q, L) - r.tip).norm());
            // A workpiece direction: the difference of two points, the frame's rotation of it.
            const Vec3 v(u(rng), u(rng), u(rng));
            worstBase = std::max(worstBase, (k.workpiecePointToBase(data, q, p + v) - k.workpiecePointToBase(data, q, p) -
                                             bw.R * v).norm());
        }
    }
    std::printf("[ engine   ] %-40s tip %.2g mm, axis %.2g, Jacobian %.2g, in the bed %.2g mm, angles taken %.2g mm\n",
                name.c_str(), worstTip, worstAxis, worstJ, worstBase, worstTaken);
    EXPECT_LT(worstTip, 1e-12) << name;  // mm, at linear commands within ±500 mm: round-off
    EXPECT_LT(worstAxis, 1e-13) << name;
    EXPECT_LT(worstJ, 1e-9) << name;
    EXPECT_LT(worstBase, 1e-12) << name;
    EXPECT_LT(worstTaken, 1e-12) << name;
}

/// Every machine of samples/machines (at least the 12 there are), in name order.
std::vector<std::filesystem::path> sampleMachineFiles() {
    std::vector<std::filesystem::path> files;
    for (const auto& e : std::filesystem::directory_iterator(test::sourcePath("samples/machines")))
        if (e.path().extension() == ".xml") files.push_back(e.path());
    std::sort(files.begin(), files.end());
    EXPECT_GE(files.size(), 12u);
    return files;
}

TEST(KinematicsEngine, MatchesTheExactKinematicsOnEverySampleMachine) {
    std::mt19937_64 rng(5);
    for (const auto& file : sampleMachineFiles()) {
        const MachineModel m = readMachineXml(file.string());
        const std::string name = file.stem().string();
        compare(m, DeviationSet(m), name + " nominal");
        compare(m, randomSet(m, rng), name + " with errors");
    }
}

TEST(KinematicsEngine, AWorkspaceFollowsItsModel) {
    // One workspace handed from one model to another (same machine, other deviations, same commands): it starts
    // empty for the second, whose cached poses would otherwise be the first's.
    const MachineModel m = readMachineXml(test::sourcePath("samples/machines/table-table-ac.xml"));
    std::mt19937_64 rng(8);
    const DeviationSet d = randomSet(m, rng);
    const KinematicsModel nominal(m, nullptr), actual(m, &d);
    KinematicsData data(nominal);
    AxisVector q(m.axisCount());
    for (int i = 0; i < m.axisCount(); ++i) q[i] = 0.1 * (i + 1);
    Vec3 tipN, axisN, tipA, axisA;
    nominal.toolPose(data, q, 100.0, tipN, axisN);
    actual.toolPose(data, q, 100.0, tipA, axisA);
    const ToolPose ref = toolPose(Kinematics(m, d), q, Kinematics(m, d).toolPoint(100.0));
    EXPECT_LT((tipA - ref.tip).norm(), 1e-12);
    EXPECT_GT((tipA - tipN).norm(), 1e-6);  // the deviations show: not the nominal pose from the cache
}

TEST(KinematicsEngine, ASetOfAnotherMachineIsRefused) {
    // The set's values are laid out for its own machine: the engine refuses another machine's set, as the exact model
    // does, instead of reading past its values. Oracle: the message written out by hand.
    const MachineModel ac = readMachineXml(test::sourcePath("samples/machines/table-table-ac.xml"));
    const MachineModel& mt = test::multitasking();
    const DeviationSet other(mt);
    for (auto arithmetic : {KinematicsModel::Arithmetic::Fast, KinematicsModel::Arithmetic::AsExactModel}) {
        try {
            const KinematicsModel model(ac, &other, arithmetic);
            ADD_FAILURE() << "another machine's set was accepted";
        } catch (const ModelError& e) {
            EXPECT_EQ(std::string(e.what()), "deviation set is for machine 'multitasking', not '" + ac.name + "'");
        }
    }
    EXPECT_THROW(Kinematics(ac, other), ModelError);
}

TEST(KinematicsEngine, InclinedRotaryAxis) {
    test::ScratchDir dir("pp-kin");
    test::writeText(dir.file("m.xml"), kInclinedHead);
    const MachineModel m = readMachineXml(dir.file("m.xml"));
    std::mt19937_64 rng(6);
    compare(m, DeviationSet(m), "inclined head nominal");
    compare(m, randomSet(m, rng), "inclined head with errors");
}

/// The exact model as its equations read, written out link by link with Eigen isometries (oracle: an independent
/// transcription of [MultiTasking] eq. (7), (10) from machine.hpp's link and deviation definitions, not from the
/// engine): link i = placement · E_location · motion(q) · E_component(q), each product taken as it comes.
struct ReferenceChain {
    const MachineModel& m;
    Eigen::VectorXd values;
    Pose walk(Side side, const AxisVector& q, JointFrames* joints = nullptr) const {
        const Chain& chain = m.chain(side);
        Pose p = Pose::Identity();
        for (int i = 0; i < static_cast<int>(chain.links.size()); ++i) {
            const Link& l = chain.links[i];
            Vec6 location = Vec6::Zero(), component = Vec6::Zero();
            bool hasComponents = false;
            for (const DeviationDef& def : m.deviations) {
                if (def.side != side || def.link != i) continue;
                if (def.kind == DeviationKind::Location) {
                    location[def.component] += values[def.offset];
                } else {
                    component[def.component] += def.basis.evaluate(q[l.axisIndex], values.data() + def.offset, l.modulo);
                    hasComponents = true;
                }
            }
            p = p * (l.placement * errorTransform(location));
            if (joints && l.kind != AxisKind::Fixed)
                joints->items[joints->count++] = {side, l.axisIndex, l.kind == AxisKind::Rotary, p.linear() * l.direction,
                                                  p.translation()};
            if (l.kind == AxisKind::Linear) p.translation() += p.linear() * (l.direction * q[l.axisIndex]);
            if (l.kind == AxisKind::Rotary) p.linear() = p.linear() * Eigen::AngleAxisd(q[l.axisIndex], l.direction).toRotationMatrix();
            if (hasComponents) p = p * errorTransform(component);
        }
        return p;
    }
};

bool sameBits(const Eigen::Ref<const Eigen::MatrixXd>& a, const Eigen::Ref<const Eigen::MatrixXd>& b) {
    if (a.rows() != b.rows() || a.cols() != b.cols()) return false;
    for (int i = 0; i < a.rows(); ++i)
        for (int j = 0; j < a.cols(); ++j)
            if (std::bit_cast<uint64_t>(a(i, j)) != std::bit_cast<uint64_t>(b(i, j))) return false;
    return true;
}

/// Arithmetic::AsExactModel with a workspace (the map's), and cnccomp::Kinematics (the same model without one), against
/// ReferenceChain, not to a tolerance but to the bit, ±0 included: chain frames, joint lines and tool pose, on poses met
/// in a grid's order (one axis stepping, the others held, a rotary axis back to earlier angles: the cache and
/// angle-table paths) and at random, nominal and with deviations (location and component errors). The tool pose's
/// reference is toolPose's definition, wMt = bMw⁻¹ · bMt, on the reference frames.
void compareBits(const MachineModel& m, const DeviationSet& d, const std::string& name) {
    const ReferenceChain ref{m, d.values};
    const Kinematics exact(m, d);
    const KinematicsModel k(m, &d, KinematicsModel::Arithmetic::AsExactModel);
    EXPECT_EQ(k.arithmetic(), KinematicsModel::Arithmetic::AsExactModel);
    KinematicsData data = k.createData();
    std::mt19937_64 rng(12);
    std::uniform_real_distribution<double> u(-1, 1);
    AxisVector q = AxisVector::Zero(m.axisCount());
    int checked = 0;
    for (int trial = 0; trial < 400; ++trial) {
        const int a = trial % m.axisCount();
        const bool rotary = m.axisLink(a).kind == AxisKind::Rotary;
        if (trial % 5 == 4) {
            for (int i = 0; i < m.axisCount(); ++i) q[i] = m.axisLink(i).kind == AxisKind::Rotary ? 3 * u(rng) : 300 * u(rng);
        } else {
            q[a] = rotary ? (trial % 7) * 0.5236 - 1.5 : 25.0 * (trial % 9) - 100;  // a grid's few values, again and again
        }
        if (trial % 11 == 0) q[a] = -0.0;
        const Frame w = k.baseToWorkpiece(data, q), t = k.baseToTool(data, q);
        JointFrames refJoints;
        const Pose rw = ref.walk(Side::Workpiece, q, &refJoints), rt = ref.walk(Side::Tool, q, &refJoints);
        EXPECT_TRUE(sameBits(w.R, rw.linear()) && sameBits(w.t, rw.translation())) << name << " workpiece frame, trial " << trial;
        EXPECT_TRUE(sameBits(t.R, rt.linear()) && sameBits(t.t, rt.translation())) << name << " tool frame, trial " << trial;
        const Pose ew = exact.baseToWorkpiece(q), et = exact.baseToTool(q);
        EXPECT_TRUE(sameBits(ew.matrix(), rw.matrix()) && sameBits(et.matrix(), rt.matrix())) << name << " Kinematics, trial " << trial;
        const JointFrames joints = exact.jointFrames(q);
        EXPECT_EQ(joints.count, refJoints.count);
        for (int j = 0; j < std::min(joints.count, refJoints.count); ++j) {
            const JointFrame &a = joints.items[j], &b = refJoints.items[j];
            EXPECT_TRUE(a.side == b.side && a.axis == b.axis && a.rotary == b.rotary && sameBits(a.direction, b.direction) &&
                        sameBits(a.point, b.point))
                << name << " joint line " << j << ", trial " << trial;
        }
        const Pose wMt = rw.inverse(Eigen::Isometry) * rt;
        for (double L : {0.0, 120.0, 360.0}) {
            Vec3 tip, axis;
            k.toolPose(data, q, L, tip, axis);
            const Vec3 refTip = wMt * Vec3(m.toolDirection * L + Vec3::Zero()), refAxis = wMt.linear() * m.toolDirection;
            EXPECT_TRUE(sameBits(tip, refTip) && sameBits(axis, refAxis)) << name << " tool pose, trial " << trial << ", L " << L;
            const ToolPose e = toolPose(exact, q, exact.toolPoint(L));
            EXPECT_TRUE(sameBits(e.tip, refTip) && sameBits(e.axis, refAxis)) << name << " toolPose, trial " << trial << ", L " << L;
            ++checked;
        }
    }
    EXPECT_EQ(checked, 1200);
}

TEST(KinematicsEngine, TheExactModelIsTheLinkByLinkTranscriptionToTheBit) {
    std::mt19937_64 rng(9);
    for (const auto& file : sampleMachineFiles()) {
        const MachineModel m = readMachineXml(file.string());
        const std::string name = file.stem().string();
        compareBits(m, DeviationSet(m), name + " nominal");
        compareBits(m, randomSet(m, rng), name + " with errors");
    }
    test::ScratchDir dir("pp-kin-bits");
    test::writeText(dir.file("m.xml"), kInclinedHead);
    const MachineModel m = readMachineXml(dir.file("m.xml"));
    compareBits(m, DeviationSet(m), "inclined head nominal");
    compareBits(m, randomSet(m, rng), "inclined head with errors");
}

/// The fast walks keep a point as three scalars (cnccomp/xyz.hpp) and write Eigen's products out term by term in its
/// order of summation; the bits are Eigen's: random matrices of mixed magnitudes and signs (not only rotations), as the
/// walks use them (the product assigned back to its operand).
TEST(KinematicsEngine, ScalarWalkArithmeticIsEigensToTheBit) {
    std::mt19937_64 rng(20261127);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::uniform_int_distribution<int> e(-30, 30);
    auto any = [&] { return std::ldexp(u(rng), e(rng)); };
    auto same = [](const Vec3& a, const xyz::Xyz& b) {
        return std::bit_cast<uint64_t>(a[0]) == std::bit_cast<uint64_t>(b.x) &&
               std::bit_cast<uint64_t>(a[1]) == std::bit_cast<uint64_t>(b.y) &&
               std::bit_cast<uint64_t>(a[2]) == std::bit_cast<uint64_t>(b.z);
    };
    int differ = 0;
    for (int k = 0; k < 200000; ++k) {
        Mat3 R;
        for (int i = 0; i < 9; ++i) R(i / 3, i % 3) = any();
        const Vec3 p(any(), any(), any());
        Vec3 a = p;
        a = R.transpose() * a;
        Vec3 b = p;
        b = R * b;
        const double c = u(rng), s = u(rng);
        Vec3 t = p;
        const double ty = t[1], tz = t[2];
        t[1] = c * ty + s * tz;
        t[2] = c * tz - s * ty;
        xyz::Xyz q = xyz::toXyz(p);
        xyz::turnBack(c, s, q.y, q.z);
        differ += !same(a, xyz::transposeTimes(R, xyz::toXyz(p))) + !same(b, xyz::times(R, xyz::toXyz(p))) + !same(t, q);
    }
    EXPECT_EQ(differ, 0);
}

}  // namespace
}  // namespace cnccomp
