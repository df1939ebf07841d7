// cnccomp verify: the plan's ball-bar runs on the true machine, before and after compensating with an identified set.
#include <cmath>

#include <fmt/format.h>

#include "cli/command.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "cnccomp/verify.hpp"

namespace cnccomp::cli {
namespace {

struct Options {
    std::string machine, plan, truth, identified;
};

void run(const Options& o) {
    const MachineModel m = readMachineXml(o.machine);
    const MeasurementPlan plan = readPlanXml(o.plan);
    const DeviationSet truth = readDeviationCsv(o.truth, m);
    const DeviationSet identified = readDeviationCsv(o.identified, m);
    const Kinematics nominal(m), actual(m, truth), model(m, identified);
    const auto rows = verifyRuns(actual, plan.runs, modelCompensation(nominal, model));
    fmt::print("verification on '{}': ball-bar runs on the true machine, as programmed and compensated with {}\n", m.name,
               o.identified);
    fmt::print("{:<16} {:>30}   {:>30}   {:>9} {:>9}\n", "run", "eccentricity before (ex ey ez)", "after (ex ey ez)",
               "span bef", "span aft");
    const auto e = [](const Vec3& v) {
        std::string s;
        for (int c = 0; c < 3; ++c) s += std::isfinite(v[c]) ? fmt::format("{:10.3f}", v[c] / kUm) : fmt::format("{:>10}", "-");
        return s;
    };
    double worstBefore = 0, worstAfter = 0;
    for (const auto& r : rows) {
        fmt::print("{:<16} {}   {}   {:9.3f} {:9.3f}\n", r.run, e(r.eccentricityBefore), e(r.eccentricityAfter),
                   r.spanBefore / kUm, r.spanAfter / kUm);
        worstBefore = std::max(worstBefore, r.spanBefore);
        worstAfter = std::max(worstAfter, r.spanAfter);
    }
    fmt::print("largest ΔL span (um): before {:.3f}, after {:.3f}\n", worstBefore / kUm, worstAfter / kUm);
}

const RegisterCommand reg([](CLI::App& app) {
    auto o = std::make_shared<Options>();
    auto* c = app.add_subcommand("verify", "Re-simulate the plan's ball-bar runs before/after compensating with an identified set");
    c->add_option("--machine", o->machine, "machine description XML")->required()->check(CLI::ExistingFile);
    c->add_option("--plan", o->plan, "measurement plan XML")->required()->check(CLI::ExistingFile);
    c->add_option("--truth", o->truth, "deviations of the real machine (CSV)")->required()->check(CLI::ExistingFile);
    c->add_option("--identified", o->identified, "identified deviations used for compensation (CSV)")->required()->check(CLI::ExistingFile);
    c->callback([o] { run(*o); });
});

}  // namespace
}  // namespace cnccomp::cli
