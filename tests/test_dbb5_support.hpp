#pragma once
// Shared fixtures of the DBB5 tests: the B/C tilting rotary table of the paper, its plan and its location truth.
#include <string>

#include "cnccomp/deviations.hpp"
#include "cnccomp/error.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "test_support.hpp"

namespace cnccomp::test {

inline const MachineModel& tableTableBc() {
    static const MachineModel m = readMachineXml(sourcePath("samples/machines/table-table-bc.xml"));
    return m;
}

inline const MeasurementPlan& dbb5PlanBc() {
    static const MeasurementPlan p = readPlanXml(sourcePath("samples/plans/dbb5-table-table-bc.xml"));
    return p;
}

/// The sample's location errors (no component errors).
inline DeviationSet dbb5TruthBc() {
    return readDeviationCsv(sourcePath("samples/deviations/dbb5-table-table-bc-truth.csv"), tableTableBc());
}

/// A run of the B/C plan by name.
inline const Dbb5Run& dbb5RunBc(const std::string& name) {
    for (const Dbb5Run& r : dbb5PlanBc().dbb5Runs)
        if (r.name == name) return r;
    throw ModelError("the B/C plan has no run " + name);
}

}  // namespace cnccomp::test
