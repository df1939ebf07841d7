#include "app/identify.hpp"

#include "app/identify_registry.hpp"
#include "cnccomp/error.hpp"
#include "cnccomp/io/plan_measurements_io.hpp"

namespace cnccomp::app {
using namespace cnccomp::identification;
using namespace cnccomp::io;
using namespace cnccomp::measurement;

IdentificationSummary identify(const MachineModel& machine, const MeasurementPlan* plan,
                               const IdentificationOptions& options) {
    // 1. The options alone, then against the machine: a misspelt solver fails at once, not after every trace of the
    //    plan was imported.
    validateOptions(options);
    MethodRequest r;
    static_cast<IdentificationOptions&>(r) = options;
    r.machine = &machine;
    r.plan = plan;
    r.formulas = options.approach == Approach::Formulas;
    if (!r.formulas) r.parsedBounds = parseBounds(machine, options.bounds);
    // 2. The method of the plan's kind, and its checks of the options against the plan.
    if (!plan) {
        if (!r.formulas)
            throw ModelError("least squares works on the raw traces: give --traces DIR and --plan P.xml (an eccentricity "
                             "table is for --method formulas)");
        if (!options.measure.empty() && options.measure != "ball-bar")
            throw ModelError("--measure needs the plan (--plan P.xml)");
    } else {
        r.kind = choosePlanMethod(*plan, options.measure);
        if (options.observe != Observe::Traces && r.kind != PlanMethod::Ballbar)
            throw ModelError("--observe eccentricity works on ball-bar <run> elements only");
    }
    const IdentificationMethod& method = identificationMethodFor(r.kind);
    method.check(r);
    // 3. The captures the method reads, once.
    const PlanMeasurements data =
        plan ? loadPlanMeasurements(machine, *plan, options.traces, method.reads(r), options.probeLog) : PlanMeasurements{};
    r.data = &data;
    // 4. The method.
    std::string tables;
    r.tables = &tables;
    IdentificationSummary out = method.run(r);
    out.methodTables = std::move(tables);
    out.method = method.name;
    out.kind = r.kind;
    out.formulas = r.formulas;
    return out;
}

}  // namespace cnccomp::app
