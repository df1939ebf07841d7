// Analytic Jacobians of the least-squares engine against central finite differences of the exact model.
#include <gtest/gtest.h>

#include "cnccomp/identification/observation.hpp"
#include "cnccomp/identification/problem.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "test_support.hpp"

namespace cnccomp {
using namespace cnccomp::identification;
using namespace cnccomp::io;
namespace {

/// Multitasking machine plus component errors of every basis type (polynomial on X and Z, Fourier on C and B,
/// table on C), so that every branch of DifferentiableMachine is exercised.
const char* kComponentMachine = R"(<?xml version="1.0"?>
<machine name="mt-components">
  <workpiece><axis name="C" type="rotary" direction="0 0 1" min="-3600" max="3600" modulo="true"/></workpiece>
  <tool direction="0 0 -1">
    <axis name="Z" type="linear" direction="0 0 1" min="-500" max="1200"/>
    <axis name="Y" type="linear" direction="0 1 0" min="-300" max="300"/>
    <axis name="X" type="linear" direction="1 0 0" min="-700" max="700"/>
    <axis name="B" type="rotary" direction="0 1 0" min="-180" max="180"/>
    <fixed name="C1"/>
  </tool>
  <deviations>
    <location name="EX0C1" link="C1" component="x"/>
    <location name="EA0C1" link="C1" component="a"/>
    <location name="EB0B" link="B" component="b"/>
    <location name="EC0Y" link="X" component="c"/>
    <location name="EX0C" link="C" component="x"/>
    <location name="EB0C" link="C" component="b"/>
    <component name="EXX" link="X" component="x" basis="polynomial" order="2"/>
    <component name="EBX" link="X" component="b" basis="polynomial" order="2"/>
    <component name="EZZ" link="Z" component="z" basis="polynomial" order="1"/>
    <component name="EXC" link="C" component="x" basis="fourier" order="2"/>
    <component name="EAC" link="C" component="a" basis="table" nodes="0 90 180 270"/>
    <component name="ECB" link="B" component="c" basis="fourier" order="1"/>
    <component name="EYB" link="B" component="y" basis="polynomial" order="2"/>
  </deviations>
</machine>)";

Observations observationsFor(const MachineModel& m, const DeviationSet& truth, bool mounting) {
    const Kinematics k(m, truth);
    std::vector<BallbarRun> runs;
    std::vector<BallbarTrace> traces;
    for (BallbarTest t : kAllBallbarTests) {
        BallbarRun r;
        r.name = std::string(testName(t));
        r.test = t;
        r.RB = 360;
        r.ZC = 300;
        r.stepDeg = 15;
        r.startDeg = rotatesHead(t) ? -90 : 0;
        r.endDeg = rotatesHead(t) ? 90 : 360;
        r.toolBallOffset = Vec3(0.01, -0.02, 0.015);
        r.workBallOffset = Vec3(-0.012, 0.008, 0.02);
        r.estimateToolBallOffset = mounting;
        r.estimateWorkBallOffset = mounting;
        traces.push_back(simulateRun(k, r));
        runs.push_back(r);
    }
    return ballbarObservations(m, runs, traces);
}

void expectJacobianMatchesDifferences(const MachineModel& m, const DeviationSet& at) {
    const Observations obs = observationsFor(m, at, true);
    std::vector<int> all;
    for (int i = 0; i < static_cast<int>(m.deviations.size()); ++i) all.push_back(i);
    const UnknownLayout layout(m, all, obs);
    const LsqProblem p(m, obs, layout, at);
    Eigen::MatrixXd Ja, Jn;
    p.jacobian(p.start(), Ja);
    p.numericJacobian(p.start(), Jn, 1e-2);
    ASSERT_EQ(Ja.rows(), Jn.rows());
    ASSERT_EQ(Ja.cols(), layout.size());
    // Columns are d(residual, mm)/d(unknown, µm or arcsec): typical entries 1e-3. Central differences with a
    // 0.01 µm step carry ~1e-12 of round-off, hence the absolute floor for the (second-order) out-of-plane offsets.
    for (int c = 0; c < Ja.cols(); ++c) {
        const double diff = (Ja.col(c) - Jn.col(c)).norm();
        EXPECT_LT(diff, 1e-6 * Jn.col(c).norm() + 1e-10) << "column " << layout[c].name << " norm " << Jn.col(c).norm();
    }
    // Every unknown is seen by at least one run of the twelve types.
    for (int c = 0; c < Ja.cols(); ++c) EXPECT_GT(Ja.col(c).norm(), 0.0) << layout[c].name;
}

TEST(LsqJacobian, BallbarLocationErrorsMatchFiniteDifferences) {
    const MachineModel& m = test::multitasking();
    // Ten times the sample truth so that the exact rotation derivatives (left Jacobian of SO(3)) matter.
    DeviationSet d = readDeviationCsv(test::sourcePath("samples/deviations/multitasking-truth.csv"), m);
    d.values *= 10.0;
    expectJacobianMatchesDifferences(m, d);
}

TEST(LsqJacobian, ComponentErrorsOfEveryBasisMatchFiniteDifferences) {
    test::ScratchDir dir("lsq-jac");
    test::writeText(dir.file("m.xml"), kComponentMachine);
    const MachineModel m = readMachineXml(dir.file("m.xml"));
    DeviationSet d(m);
    for (int i = 0; i < d.values.size(); ++i) d.values[i] = 2e-4 * std::sin(1.7 * i + 0.3);  // mixed signs
    for (const DeviationDef& def : m.deviations)  // polynomial coefficients: sensible sizes at the travel ends
        if (def.kind == DeviationKind::Component && def.basis.type == ComponentBasis::Type::Polynomial)
            for (int k = 0; k < def.size(); ++k) d.values[def.offset + k] *= std::pow(1e-2, k + 1);
    expectJacobianMatchesDifferences(m, d);
}

TEST(LsqJacobian, ToolPointJacobianMatchesKinematics) {
    // d(toolPointInWorkpiece)/d(values) for a generic pose with every axis moved.
    const MachineModel& m = test::multitasking();
    DeviationSet d = readDeviationCsv(test::sourcePath("samples/deviations/multitasking-truth.csv"), m);
    d.values *= 100.0;
    const DifferentiableMachine dm(m, d);
    AxisVector q(m.axisCount());
    for (int i = 0; i < q.size(); ++i) q[i] = 0.3 + 0.2 * i;
    const Vec3 P(1.5, -2.0, -250.0);
    std::vector<int> flat;
    for (int i = 0; i < m.parameterCount(); ++i) flat.push_back(i);
    Eigen::MatrixXd J(3, flat.size());
    dm.toolPointJacobian(q, P, flat, J);
    const double h = 1e-7;
    for (int i = 0; i < m.parameterCount(); ++i) {
        DeviationSet a = d, b = d;
        a.values[i] += h;
        b.values[i] -= h;
        const Vec3 fd = (Kinematics(m, a).toolPointInWorkpiece(q, P) - Kinematics(m, b).toolPointInWorkpiece(q, P)) / (2 * h);
        EXPECT_LT((J.col(i) - fd).norm(), 1e-6 * std::max(1.0, fd.norm())) << m.deviations[i].name;
    }
}

}  // namespace
}  // namespace cnccomp
