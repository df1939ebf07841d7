#pragma once
// R-test runs of a sample plan simulated on a sample machine with a sample deviation set (noise-free), computed once:
// the fixture of the R-test method tests.
#include <string>
#include <vector>

#include "cnccomp/identification/rtest_run.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "test_support.hpp"

namespace cnccomp::test {

struct RtestFixture {
    measurement::MeasurementPlan plan;
    DeviationSet truth;
    std::vector<identification::RtestTrace> traces;
};

/// samples/plans/<plan>.xml simulated on samples/machines/<machine>.xml with samples/deviations/<truth>.csv.
inline RtestFixture makeRtestFixture(const std::string& machine, const std::string& plan, const std::string& truth) {
    const MachineModel& m = sampleMachine(machine);
    RtestFixture x{io::readPlanXml(sourcePath("samples/plans/" + plan + ".xml")),
                   io::readDeviationCsv(sourcePath("samples/deviations/" + truth + ".csv"), m), {}};
    const Kinematics k(m, x.truth);
    for (const measurement::RtestRun& r : x.plan.rtestRuns) x.traces.push_back(identification::simulateRtest(k, r));
    return x;
}

}  // namespace cnccomp::test
