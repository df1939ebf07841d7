#pragma once
// Shared fixtures of the DBB5 tests: the B/C tilting rotary table of the paper, its plan and its location truth.
#include <random>
#include <string>

#include "cnccomp/deviations.hpp"
#include "cnccomp/identification/dbb5_observation.hpp"
#include "cnccomp/units.hpp"
#include "cnccomp/error.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "test_support.hpp"

namespace cnccomp::test {

inline const MachineModel& tableTableBc() {
    static const MachineModel m = io::readMachineXml(sourcePath("samples/machines/table-table-bc.xml"));
    return m;
}

inline const measurement::MeasurementPlan& dbb5PlanBc() {
    static const measurement::MeasurementPlan p = io::readPlanXml(sourcePath("samples/plans/dbb5-table-table-bc.xml"));
    return p;
}

/// The sample's location errors (no component errors).
inline DeviationSet dbb5TruthBc() {
    return io::readDeviationCsv(sourcePath("samples/deviations/dbb5-table-table-bc-truth.csv"), tableTableBc());
}

/// A run of the B/C plan by name.
inline const measurement::Dbb5Run& dbb5RunBc(const std::string& name) {
    for (const measurement::Dbb5Run& r : dbb5PlanBc().dbb5Runs)
        if (r.name == name) return r;
    throw ModelError("the B/C plan has no run " + name);
}

/// The observations of every run of the B/C plan simulated on `truth` with Gaussian noise of `noiseUm` per sample.
inline identification::Observations simulateBc(const DeviationSet& truth, double noiseUm, unsigned seed) {
    const MachineModel& m = tableTableBc();
    const Kinematics k(m, truth);
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> noise(0.0, noiseUm * kUm);
    std::vector<BallbarTrace> traces;
    for (const measurement::Dbb5Run& r : dbb5PlanBc().dbb5Runs) {
        BallbarTrace t = identification::simulateDbb5(k, r);
        if (noiseUm > 0)
            for (double& v : t.dL) v += noise(rng);
        traces.push_back(t);
    }
    return identification::dbb5Observations(m, dbb5PlanBc().dbb5Runs, traces);
}

}  // namespace cnccomp::test
