// cnccomp simulate-runs: every run of a plan, of every kind (ball bar, absolute ball bar, R-test, DBB5), on a machine
// with known deviations; one CSV per run.
#include <filesystem>
#include <random>

#include <fmt/format.h>

#include "cli/command.hpp"
#include "cnccomp/error.hpp"
#include "cnccomp/identification/seed002_tilting_head.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "cnccomp/io/rtest_csv.hpp"
#include "cnccomp/io/text_util.hpp"
#include "cnccomp/io/trace_csv.hpp"

namespace cnccomp::cli {
namespace {

struct Options {
    std::string machine, plan, deviations, out;
    double noiseUm = 0.0;
    unsigned long seed = 1;
};

void run(const Options& o) {
    const MachineModel m = readMachineXml(o.machine);
    const MeasurementPlan plan = readPlanXml(o.plan);
    const DeviationSet d = o.deviations.empty() ? DeviationSet(m) : readDeviationCsv(o.deviations, m);
    if (!(o.noiseUm >= 0)) throw ModelError("--noise-um must be zero or positive");
    std::filesystem::create_directories(o.out);
    const Kinematics k(m, d);
    std::mt19937_64 rng(o.seed);
    std::normal_distribution<double> noise(0.0, o.noiseUm * kUm);
    const auto file = [&](const std::string& name) {
        const std::string path = (std::filesystem::path(o.out) / (name + ".csv")).string();
        refuseToOverwrite(path, {o.machine, o.plan, o.deviations});
        return path;
    };
    const auto trace = [&](const std::string& name, BallbarTrace t, const char* kind) {
        if (o.noiseUm > 0)
            for (double& v : t.dL) v += noise(rng);
        writeTraceCsv(file(name), t);
        fmt::print("{:<16} {:<16} {:>6} samples\n", name, kind, t.dL.size());
    };
    for (const BallbarRun& r : plan.runs) trace(r.name, simulateRun(k, r), "ball bar");
    for (const BallbarRun& r : plan.absoluteRuns) trace(r.name, simulateAbsoluteRun(k, r), "absolute bar");
    for (const Dbb5Run& r : plan.dbb5Runs) trace(r.name, simulateDbb5(k, r), "DBB5");
    for (const RtestRun& r : plan.rtestRuns) {
        RtestTrace t = simulateRtest(k, r);
        if (o.noiseUm > 0)
            for (Vec3& v : t.d) v += Vec3(noise(rng), noise(rng), noise(rng));
        writeRtestCsv(file(r.name), m, t);
        fmt::print("{:<16} {:<16} {:>6} poses\n", r.name, "R-test", t.d.size());
    }
    fmt::print("simulated {} runs on '{}' into {}\n", plan.runCount(), m.name, o.out);
}

const RegisterCommand reg([](CLI::App& app) {
    auto o = std::make_shared<Options>();
    auto* c = app.add_subcommand("simulate-runs",
                                 "Simulate every run of a plan (ball bar, absolute ball bar, R-test, DBB5); one CSV per run");
    c->add_option("--machine", o->machine, "machine description XML")->required()->check(CLI::ExistingFile);
    c->add_option("--plan", o->plan, "measurement plan XML")->required()->check(CLI::ExistingFile);
    c->add_option("--deviations", o->deviations, "deviation set CSV (the truth); none = nominal machine")->check(CLI::ExistingFile);
    c->add_option("--out", o->out, "output folder")->required();
    c->add_option("--noise-um", o->noiseUm, "Gaussian noise on every ΔL sample / displacement component, σ in um");
    c->add_option("--seed", o->seed, "random seed for the noise");
    c->callback([o] { run(*o); });
});

}  // namespace
}  // namespace cnccomp::cli
