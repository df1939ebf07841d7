// cnccomp plan: propose the ball-bar runs that make a list of deviations identifiable .
#include <cmath>

#include <fmt/format.h>

#include "cli/command.hpp"
#include "cnccomp/error.hpp"
#include "cnccomp/identification/parameters.hpp"
#include "cnccomp/identification/planner.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "cnccomp/io/text_util.hpp"

namespace cnccomp::cli {
using namespace cnccomp::identification;
using namespace cnccomp::io;
namespace {

struct Options {
    std::string machine, identify, candidates, out;
    std::string lb = "100", rb = "360,410", rc = "50", zc = "300,340", mounting = "none", observe = "traces";
    double step = 1.0, evalStep = 10.0, targetCondition = 300.0;
    int maxRuns = 10;
};

std::vector<double> numbers(const std::string& text, const char* option) {
    std::vector<double> v;
    for (const std::string& item : commaItems(text)) {
        const auto x = parseNumber(item);
        if (!x || !std::isfinite(*x) || *x <= 0)
            throw ModelError(fmt::format("{}: '{}' is not a positive length in mm", option, item));
        v.push_back(*x);
    }
    if (v.empty()) throw ModelError(fmt::format("{} needs at least one value", option));
    return v;
}

std::vector<BallbarTest> parseTypes(const std::string& text) {
    std::vector<BallbarTest> v;
    for (const std::string& item : commaItems(text)) {
        if (item == "all") {
            for (BallbarTest t : kAllBallbarTests) v.push_back(t);
            continue;
        }
        const auto t = parseTest(item);
        if (!t) {
            std::string known;
            for (BallbarTest k : kAllBallbarTests) known += (known.empty() ? "" : ", ") + std::string(testName(k));
            throw ModelError(fmt::format("--candidates: unknown run type '{}' (known: {})", item, known));
        }
        v.push_back(*t);
    }
    return v;
}

std::string joined(const std::vector<std::string>& v) {
    std::string s;
    for (const std::string& x : v) s += (s.empty() ? "" : ", ") + x;
    return s.empty() ? "-" : s;
}

void run(const Options& o) {
    const MachineModel m = readMachineXml(o.machine);
    refuseToOverwrite(o.out, {o.machine});
    PlannerOptions po;
    po.identify = parseDeviationList(m, o.identify);
    if (!o.candidates.empty()) po.types = parseTypes(o.candidates);
    po.LB = numbers(o.lb, "--lb");
    po.RB = numbers(o.rb, "--rb");
    po.RC = numbers(o.rc, "--rc");
    po.ZC = numbers(o.zc, "--zc");
    po.planStepDeg = o.step;
    po.evaluationStepDeg = o.evalStep;
    po.mounting = o.mounting;
    po.observe = o.observe;
    po.maxRuns = o.maxRuns;
    po.targetCondition = o.targetCondition;
    const PlanProposal p = proposePlan(m, po);

    fmt::print("{} of {} candidate runs fit machine '{}'\n", p.candidates - p.rejected.size(), p.candidates, m.name);
    for (const std::string& s : p.rejected) fmt::print("  rejected {}\n", s);
    for (const std::string& s : p.steps) fmt::print("  {}\n", s);
    if (!p.complete) {
        fmt::print("the candidates cannot identify the whole request (rank {}/{}); the plan below is the best found\n",
                   p.rank, p.unknowns);
    }
    fmt::print("plan: {} run(s), rank {}/{}, condition number {:.4g} -> {}\n", p.plan.runs.size(), p.rank, p.unknowns,
               p.conditionNumber, o.out);
    for (const BallbarRun& r : p.plan.runs) fmt::print("  {}\n", r.name);
    fmt::print("{:<8} {:<6} {:>12}  {:<40} {}\n", "name", "alias", "sigma/um", "needs (cannot do without)", "seen by");
    for (const DeviationNeed& n : p.needs) {
        const std::string unit = m.deviations[n.deviation].isAngle() ? "arcsec" : "um";
        if (n.identified)
            fmt::print("{:<8} {:<6} {:>12}  {:<40} {}\n", n.name, n.alias, fmt::format("{:.4f} {}", n.sigmaPerUm, unit),
                       joined(n.needs), joined(n.seenBy));
        else
            fmt::print("{:<8} {:<6} {:>12}  {}\n", n.name, n.alias, "NOT IDENTIFIED",
                       n.confoundedWith.empty() ? std::string("unobservable on its own")
                                                : "confounded with " + joined(n.confoundedWith));
    }
    if (!p.others.empty()) fmt::print("deviations not requested:\n");
    for (const ExtraAdvice& a : p.others) {
        const std::string unit = m.deviations[a.deviation].isAngle() ? "arcsec" : "um";
        std::string label = a.alias.empty() ? a.name : fmt::format("{} ({})", a.name, a.alias);
        label += a.seenByTypes.empty() ? " [seen by no candidate run]" : fmt::format(" [seen by {} runs]", joined(a.seenByTypes));
        if (a.identifiedByPlan) {
            fmt::print("  {}: also identified by this plan (sigma {:.4f} {} per um), needs {}\n", label, a.sigmaPerUm, unit,
                       joined(a.needs));
        } else if (!a.extraRuns.empty()) {
            std::string best;
            for (size_t i = 0; i < a.extraRuns.size() && i < 3; ++i)
                best += fmt::format("{}{} (sigma {:.4f} {} per um)", i ? ", " : "", a.extraRuns[i], a.extraSigmaPerUm[i], unit);
            fmt::print("  {}: not identified by this plan; add one of {}{}\n", label, best,
                       a.extraRuns.size() > 3 ? fmt::format(" or {} more", a.extraRuns.size() - 3) : "");
        } else {
            fmt::print("  {}: not identified by this plan, and no single extra candidate run identifies it\n", label);
        }
    }
    writePlanXml(o.out, p.plan);
}

const RegisterCommand reg([](CLI::App& app) {
    auto o = std::make_shared<Options>();
    auto* c = app.add_subcommand("plan", "Propose ball-bar runs that make the listed deviations identifiable");
    c->add_option("--machine", o->machine, "machine description XML")->required()->check(CLI::ExistingFile);
    c->add_option("--identify", o->identify, "deviations to identify: ISO names or aliases (comma list), or all")->required();
    c->add_option("--candidates", o->candidates,
                  "candidate run types (comma list, e.g. B-X,B-Y,C-radial); default every type the machine allows");
    c->add_option("--lb", o->lb, "candidate ball-bar lengths LB, mm (comma list)")->capture_default_str();
    c->add_option("--rb", o->rb, "candidate tool lengths RB, mm")->capture_default_str();
    c->add_option("--rc", o->rc, "candidate radii RC of the W-side ball from the C axis, mm")->capture_default_str();
    c->add_option("--zc", o->zc, "candidate heights ZC of the W-side ball above the table, mm")->capture_default_str();
    c->add_option("--step", o->step, "angle step written into the plan, deg")->capture_default_str();
    c->add_option("--evaluation-step", o->evalStep, "angle step used to rate the candidates, deg")->capture_default_str();
    c->add_option("--mounting", o->mounting, "estimate-mounting of every run: none, tool, work, both")->capture_default_str();
    c->add_option("--observe", o->observe,
                  "what the identification will use: traces (raw samples, least squares) or eccentricity (circle "
                  "centres, as the ball-bar eccentricity formulas)")
        ->capture_default_str();
    c->add_option("--max-runs", o->maxRuns, "largest number of runs")->capture_default_str();
    c->add_option("--target-condition", o->targetCondition, "condition number to reach (scaled um / arcsec)")
        ->capture_default_str();
    c->add_option("--out", o->out, "plan XML to write")->required();
    c->callback([o] { run(*o); });
});

}  // namespace
}  // namespace cnccomp::cli
