#pragma once
// The identification methods, one per kind of plan (identification/plan_method.hpp), looked up by name or by the kind
// of plan they serve, as the controllers' backends are (controllers/backend.hpp, controllers/registry.cpp). Each method
// states the runs it reads, checks the options against the plan before any file is read, then runs on the plan's
// captures read once (measurement/plan_measurements.hpp). The façade (identify.hpp) is the caller.
#include <iterator>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "app/identify_options.hpp"
#include "app/identify_summary.hpp"
#include "cnccomp/identification/plan_method.hpp"
#include "cnccomp/measurement/plan.hpp"
#include "cnccomp/measurement/plan_measurements.hpp"

namespace cnccomp::app {

/// What a method is given: the options, the machine, the plan and, once read, its captures.
struct MethodRequest : IdentificationOptions {
    const MachineModel* machine = nullptr;
    const measurement::MeasurementPlan* plan = nullptr;  ///< null only for ball-bar formulas from an eccentricity table
    identification::PlanMethod kind = identification::PlanMethod::Ballbar;
    bool formulas = false;                  ///< approach == Approach::Formulas
    std::vector<identification::ParameterBound> parsedBounds;  ///< `bounds` parsed against the machine
    const measurement::PlanMeasurements* data = nullptr;    ///< set before run()
    std::string* tables = nullptr;             ///< IdentificationSummary::methodTables, appended to by say()
    /// Appends to the method's tables (what it finds as it works, in order).
    template <class... Args>
    void say(fmt::format_string<Args...> format, Args&&... args) const {
        fmt::format_to(std::back_inserter(*tables), format, std::forward<Args>(args)...);
    }
};

struct IdentificationMethod {
    std::string name;                 ///< as planMethodName() of the kind it serves, e.g. "rtest-location"
    std::vector<identification::PlanMethod> serves;   ///< the kinds of plan it identifies
    std::string description;
    /// The kinds of runs it reads for this request (the façade reads them once, before run()).
    measurement::MeasurementKinds (*reads)(const MethodRequest&) = nullptr;
    /// Checks the options against the machine and the plan (nothing read). ModelError naming the option.
    void (*check)(const MethodRequest&) = nullptr;
    /// Identifies from request.data. ModelError / InputError naming what does not fit.
    IdentificationSummary (*run)(const MethodRequest&) = nullptr;
};

/// Every registered method, in registration order.
const std::vector<IdentificationMethod>& identificationMethods();
/// The method of that name; ModelError listing the registered names.
const IdentificationMethod& identificationMethod(std::string_view name);
/// The method serving that kind of plan; ModelError listing the registered methods and what they serve.
const IdentificationMethod& identificationMethodFor(identification::PlanMethod kind);

/// The built-in methods, listed by identificationMethods() (an explicit list, not objects registering themselves from
/// their files: this is a static library linked without --whole-archive, and the linker drops an object file nobody
/// names). identify_methods.cpp: the rotary-axis and ball-bar methods; identify_circle.cpp: the linear-axis circles.
std::vector<IdentificationMethod> rotaryAxisMethods();
IdentificationMethod linearCircleMethod();

}  // namespace cnccomp::app
