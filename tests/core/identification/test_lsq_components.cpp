// Position-dependent component errors (polynomial, Fourier and table bases, ISO 230-1 EXX … ECC) identified by the
// least-squares engine from raw ball-bar traces: every identifiable coefficient is recovered, every confounded
// group is reported as named combinations whose values match the truth.
#include <gtest/gtest.h>

#include "cnccomp/identification/lsq.hpp"
#include "cnccomp/identification/parameters.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "test_support.hpp"

namespace cnccomp {
using namespace cnccomp::identification;
using namespace cnccomp::io;
namespace {

const char* kMachine = R"(<?xml version="1.0"?>
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
    <location name="EZ0C1" link="C1" component="z"/>
    <location name="EC0B" link="B" component="c"/>
    <location name="EX0C" link="C" component="x"/>
    <location name="EY0C" link="C" component="y"/>
    <component name="EXC" link="C" component="x" basis="fourier" order="2"/>
    <component name="EAC" link="C" component="a" basis="fourier" order="2"/>
    <component name="EXX" link="X" component="x" basis="polynomial" order="2"/>
    <component name="EZB" link="B" component="z" basis="table" nodes="-180 -90 0 90"/>
  </deviations>
</machine>)";

TEST(LsqComponents, FourierPolynomialAndTableCoefficientsRoundTrip) {
    test::ScratchDir dir("lsq-components");
    test::writeText(dir.file("m.xml"), kMachine);
    const MachineModel m = readMachineXml(dir.file("m.xml"));
    DeviationSet truth(m);
    truth.set("EZ0C1", 6 * kUm);
    truth.set("EC0B", 4 * kArcsec);
    truth.set("EX0C", -7 * kUm);
    truth.set("EY0C", 5 * kUm);
    const auto setCoef = [&](const char* name, std::vector<double> v) {
        const DeviationDef& d = m.deviations[m.deviationIndex(name)];
        for (size_t k = 0; k < v.size(); ++k) truth.values[d.offset + static_cast<int>(k)] = v[k];
    };
    setCoef("EXC", {3 * kUm, -2 * kUm, 1.5 * kUm, 2.5 * kUm});
    setCoef("EAC", {4 * kArcsec, -3 * kArcsec, 2 * kArcsec, 1 * kArcsec});
    setCoef("EXX", {20e-6, 8e-9});  // 20 µm/m linear scale error, 8 µm/m² (≈ 2 µm at 500 mm)
    setCoef("EZB", {3 * kUm, -2 * kUm, 0, 4 * kUm});

    std::vector<BallbarRun> runs = readPlanXml(test::sourcePath("samples/plans/multitasking-six-circles.xml")).runs;
    for (BallbarTest t : {BallbarTest::CX, BallbarTest::CY, BallbarTest::CZ, BallbarTest::BZ}) {
        BallbarRun r = runs[0];
        r.test = t;
        r.name = std::string(testName(t));
        r.startDeg = rotatesHead(t) ? -180 : 0;
        r.endDeg = rotatesHead(t) ? 180 : 360;
        runs.push_back(r);
    }
    const Kinematics k(m, truth);
    std::vector<BallbarTrace> traces;
    for (BallbarRun& r : runs) {
        r.stepDeg = 5;
        traces.push_back(simulateRun(k, r));
    }
    const IdentificationResult r = identify(m, ballbarObservations(m, runs, traces));
    const IdentificationReport& rep = r.report;
    EXPECT_TRUE(rep.converged) << rep.termination;
    EXPECT_EQ(rep.unknowns, 4 + 4 + 4 + 2 + 4);
    const auto trueValue = [&](const std::string& name) {
        const size_t open = name.find('[');
        const DeviationDef& d = m.deviations[m.deviationIndex(name.substr(0, open))];
        const int coef = open == std::string::npos ? 0 : std::stoi(name.substr(open + 1));
        return truth.values[d.offset + coef];
    };
    int identified = 0;
    for (const ParameterEstimate& p : rep.parameters) {
        if (!p.identified) continue;
        ++identified;
        const double unit = p.name.rfind("EXX", 0) == 0 ? coefficientScale(m, m.deviations[m.deviationIndex("EXX")],
                                                                            p.name == "EXX[0]" ? 0 : 1)
                                                        : p.displayScale();
        EXPECT_LT(std::abs(p.value - trueValue(p.name)) / unit, 1e-3) << p.name;
    }
    // Second harmonics, the X scale polynomial and the B-head squareness are identified on their own.
    EXPECT_EQ(identified, 7);
    for (const char* n : {"EC0B", "EXC[2]", "EXC[3]", "EAC[2]", "EAC[3]", "EXX[0]", "EXX[1]"})
        EXPECT_TRUE(rep.parameters[rep.find(n)].identified) << n;
    // Three blind directions, each named: a constant EZB table offset is the spindle offset EZ0C1; the first
    // Fourier harmonics of EXC and EAC (at ZC = 300 mm) act like the C-axis offsets EX0C, EY0C. The reported
    // identifiable combinations (e.g. "EX0C + 300·EAC[1]") hold the true values.
    EXPECT_EQ(rep.rank, rep.unknowns - 3);
    ASSERT_EQ(rep.unobservable.size(), 3u);
    EXPECT_EQ(rep.unobservable[0].text, "EZ0C1 - EZB[0] - EZB[1] - EZB[2] - EZB[3]");
    ASSERT_FALSE(rep.identifiable.empty());
    for (const Combination& c : rep.identifiable) {
        double v = 0;
        for (size_t i = 0; i < c.names.size(); ++i) v += c.coefficients[i] * trueValue(c.names[i]);
        EXPECT_NEAR(c.value, v, 1e-3 * (c.angle ? kArcsec : kUm)) << c.text;
    }
}

}  // namespace
}  // namespace cnccomp
