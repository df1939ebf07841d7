// cnccomp simulate: ball-bar traces of a plan on a machine with known deviations.
#include <filesystem>
#include <random>

#include <fmt/format.h>

#include "cli/command.hpp"
#include "cnccomp/eccentricity.hpp"
#include "cnccomp/error.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/eccentricity_csv.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "cnccomp/io/plan_xml.hpp"
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
    std::vector<BallbarTrace> traces;
    for (const BallbarRun& r : plan.runs) {
        BallbarTrace t = simulateRun(k, r);
        if (o.noiseUm > 0)
            for (double& v : t.dL) v += noise(rng);
        const std::string path = (std::filesystem::path(o.out) / (r.name + ".csv")).string();
        refuseToOverwrite(path, {o.machine, o.plan, o.deviations});
        writeTraceCsv(path, t, r, m.name);  // with the run's metadata, checked when read back
        traces.push_back(std::move(t));
    }
    const auto rows = eccentricitiesFromTraces(m, plan.runs, traces);
    const std::string ecc = (std::filesystem::path(o.out) / "eccentricities.csv").string();
    writeEccentricityCsv(ecc, rows);
    fmt::print("simulated {} runs on '{}' into {}\n", plan.runs.size(), m.name, o.out);
    fmt::print("{:<16} {:>10} {:>10} {:>10}   (eccentricity, um)\n", "run", "ex", "ey", "ez");
    const auto cell = [](double v) { return std::isfinite(v) ? fmt::format("{:10.3f}", v / kUm) : fmt::format("{:>10}", "-"); };
    for (size_t i = 0; i < rows.size(); ++i)
        fmt::print("{:<16} {} {} {}\n", plan.runs[i].name, cell(rows[i].e[0]), cell(rows[i].e[1]), cell(rows[i].e[2]));
}

const RegisterCommand reg([](CLI::App& app) {
    auto o = std::make_shared<Options>();
    auto* c = app.add_subcommand("simulate", "Simulate the ball-bar runs of a plan; write one trace CSV per run and eccentricities.csv");
    c->add_option("--machine", o->machine, "machine description XML")->required()->check(CLI::ExistingFile);
    c->add_option("--plan", o->plan, "measurement plan XML")->required()->check(CLI::ExistingFile);
    c->add_option("--deviations", o->deviations, "deviation set CSV (the truth); none = nominal machine")->check(CLI::ExistingFile);
    c->add_option("--out", o->out, "output folder")->required();
    c->add_option("--noise-um", o->noiseUm, "Gaussian noise on every ΔL sample, standard deviation in um");
    c->add_option("--seed", o->seed, "random seed for the noise");
    c->callback([o] { run(*o); });
});

}  // namespace
}  // namespace cnccomp::cli
