// cnccomp simulate: every run of a plan, of every kind (ball bar, absolute ball bar, R-test, DBB5, linear-axis circle), on a machine with
// known deviations; one CSV per run (ball-bar runs with their metadata, which the import checks), and eccentricities.csv
// for the ball-bar runs. Everything is computed, then every file is staged and committed together (io/output_set.hpp):
// a failing run leaves no output.
// --instrument time|angle: the ball-bar runs written as an instrument exports them instead (the plan's capture: passes
// and directions, overshoot, columns, units; io/trace_export.hpp), a simulated measurement standing in for the ball
// bar that `identify` imports like a measured one.
#include <cmath>
#include <filesystem>
#include <functional>
#include <random>

#include <fmt/format.h>

#include "cli/command.hpp"
#include "cnccomp/eccentricity.hpp"
#include "cnccomp/error.hpp"
#include "cnccomp/identification/tilting_head_errors.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/eccentricity_csv.hpp"
#include "cnccomp/io/linear_circle_trace.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "cnccomp/io/output_set.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "cnccomp/io/rtest_csv.hpp"
#include "cnccomp/io/text_util.hpp"
#include "cnccomp/io/trace_csv.hpp"
#include "cnccomp/io/trace_export.hpp"
#include "cnccomp/identification/dbb5_run.hpp"
#include "cnccomp/identification/sphere_probe.hpp"
#include "cnccomp/io/probe_log.hpp"

namespace cnccomp::cli {
using namespace cnccomp::identification;
using namespace cnccomp::io;
using namespace cnccomp::measurement;
namespace {

struct Options {
    std::string machine, plan, deviations, out, instrument, probeLog = "cnccomp-probe.txt";
    double noiseUm = 0.0;
    unsigned long seed = 1;
};

/// One output file, computed and waiting to be staged.
struct Pending {
    std::string name, run, kind;  ///< file name in the output folder; run name ("" for the eccentricity table)
    size_t samples = 0;
    std::function<void(std::ostream&)> write;
};

void run(const Options& o) {
    const MachineModel m = readMachineXml(o.machine);
    const MeasurementPlan plan = readPlanXml(o.plan);
    const DeviationSet d = o.deviations.empty() ? DeviationSet(m) : readDeviationCsv(o.deviations, m);
    if (!(o.noiseUm >= 0) || !std::isfinite(o.noiseUm)) throw ModelError("--noise-um must be zero or positive");
    if (plan.runCount() == 0) throw ModelError(fmt::format("plan '{}' has no runs", o.plan));
    if (!o.instrument.empty() && o.instrument != "time" && o.instrument != "angle")
        throw InputError("--instrument", 0, fmt::format("'{}' is not time or angle", o.instrument));
    if (!o.instrument.empty() && plan.runs.empty() && plan.circleRuns.empty())
        throw ModelError(fmt::format("--instrument: plan '{}' has no ball-bar runs", o.plan));
    const Kinematics k(m, d);
    std::mt19937_64 rng(o.seed);
    std::normal_distribution<double> noise(0.0, o.noiseUm * kUm);
    std::vector<Pending> pending;
    std::vector<BallbarTrace> ballbar;
    // Noise on every sample of the passes an instrument records; the number of samples.
    const auto noisyPasses = [&](std::vector<DirectedTrace>& passes) {
        size_t n = 0;
        for (DirectedTrace& p : passes) {
            if (o.noiseUm > 0)
                for (double& v : p.trace.dL) v += noise(rng);
            n += p.trace.dL.size();
        }
        return n;
    };
    const auto addTrace = [&](const std::string& name, BallbarTrace t, const char* kind, const BallbarRun* run) {
        if (o.noiseUm > 0)
            for (double& v : t.dL) v += noise(rng);
        if (std::string(kind) == "ball bar") ballbar.push_back(t);
        const size_t n = t.dL.size();
        // Ball-bar runs carry their metadata (run, machine, geometry), which the import checks against the plan.
        std::string text = formatTraceCsv(t, run, run ? m.name : std::string());
        pending.push_back({name + ".csv", name, kind, n, [text = std::move(text)](std::ostream& out) { out << text; }});
    };
    if (o.instrument.empty()) {
        for (const BallbarRun& r : plan.runs) addTrace(r.name, simulateRun(k, r), "ball bar", &r);
    } else {
        // As the instrument records and exports them: every pass of the capture, overshoot included, noise on every sample.
        for (const BallbarRun& r : plan.runs) {
            std::vector<DirectedTrace> passes = simulateCapturedPasses(k, r);
            const size_t n = noisyPasses(passes);
            std::string text = formatCapturedTrace(r, passes, o.instrument == "time", m.name);
            pending.push_back({r.name + ".csv", r.name, o.instrument + "-sampled", n,
                               [text = std::move(text)](std::ostream& out) { out << text; }});
        }
    }
    // Circles of the linear axes: always as the instrument records them (both passes with their feed-in and feed-out
    // arcs), angle-sampled unless --instrument time.
    for (const LinearCircleRun& r : plan.circleRuns) {
        std::vector<DirectedTrace> passes = simulateLinearCircle(k, r);
        const size_t n = noisyPasses(passes);
        std::string text = formatLinearCircleTrace(r, passes, o.instrument == "time", m.name);
        pending.push_back({r.name + ".csv", r.name, "circle " + std::string(linearPlaneName(r.plane)), n,
                           [text = std::move(text)](std::ostream& out) { out << text; }});
    }
    for (const BallbarRun& r : plan.absoluteRuns) addTrace(r.name, simulateAbsoluteRun(k, r), "absolute bar", &r);
    for (const Dbb5Run& r : plan.dbb5Runs) addTrace(r.name, simulateDbb5(k, r), "DBB5", nullptr);
    for (const RtestRun& r : plan.rtestRuns) {
        RtestTrace t = simulateRtest(k, r);
        if (o.noiseUm > 0)
            for (Vec3& v : t.d) v += Vec3(noise(rng), noise(rng), noise(rng));
        const size_t n = t.d.size();
        pending.push_back({r.name + ".csv", r.name, "R-test", n,
                           [&m, t = std::move(t)](std::ostream& out) { writeRtestCsv(out, m, t); }});
    }
    if (!plan.sphereRuns.empty()) {
        // One result file for every sphere run, as the probing program's LOG lines give it (9 decimals instead of
        // LinuxCNC's 6); noise moves each trigger along its probing move.
        const SpherePlanCommands cmds = sphereCommands(m, plan.sphereRuns);
        const ProbeLog log = simulateSphereProbing(k, cmds, o.noiseUm * kUm, o.seed);
        std::string text = formatProbeLog(log, m, 9);
        pending.push_back({o.probeLog, "(sphere)", "probe touches", log.touches.size(),
                           [text = std::move(text)](std::ostream& out) { out << text; }});
    }
    std::vector<EccentricityRow> rows;
    if (!plan.runs.empty() && o.instrument.empty()) {
        rows = eccentricitiesFromTraces(m, plan.runs, ballbar);
        pending.push_back({"eccentricities.csv", "", "", rows.size(),
                           [&rows](std::ostream& out) { writeEccentricityCsv(out, rows); }});
    }
    // Every run is computed: stage every file (a run name never leaves the folder), then commit them together.
    OutputSet staged({o.machine, o.plan, o.deviations});
    staged.makeFolder(o.out);
    for (const Pending& p : pending) staged.add(OutputSet::fileIn(o.out, p.name, o.plan), p.write);
    staged.commit();

    fmt::print("simulated {} runs on '{}' into {}\n", plan.runCount(), m.name, o.out);
    for (const Pending& p : pending)
        if (!p.run.empty())
            fmt::print("{:<16} {:<14} {:>6} {}\n", p.run, p.kind, p.samples, p.kind == "R-test" ? "poses" : p.kind == "probe touches" ? "touches" : "samples");
    if (rows.empty()) return;
    fmt::print("{:<16} {:>10} {:>10} {:>10}   (eccentricity of the ball-bar runs, um)\n", "run", "ex", "ey", "ez");
    const auto cell = [](double v) { return std::isfinite(v) ? fmt::format("{:10.3f}", v / kUm) : fmt::format("{:>10}", "-"); };
    for (size_t i = 0; i < rows.size(); ++i)
        fmt::print("{:<16} {} {} {}\n", plan.runs[i].name, cell(rows[i].e[0]), cell(rows[i].e[1]), cell(rows[i].e[2]));
}

const RegisterCommand reg([](CLI::App& app) {
    auto o = std::make_shared<Options>();
    auto* c = app.add_subcommand("simulate",
                                 "Simulate every run of a plan (ball bar, absolute ball bar, R-test, DBB5, linear-axis circle, sphere probing): "
                                 "one CSV per run, eccentricities.csv for ball-bar runs, the probe result file for sphere runs; nothing is written unless every run succeeds");
    c->add_option("--machine", o->machine, "machine description XML")->required()->check(CLI::ExistingFile);
    c->add_option("--plan", o->plan, "measurement plan XML")->required()->check(CLI::ExistingFile);
    c->add_option("--deviations", o->deviations, "deviation set CSV (the truth); none = nominal machine")->check(CLI::ExistingFile);
    c->add_option("--out", o->out, "output folder")->required();
    c->add_option("--noise-um", o->noiseUm, "Gaussian noise on every ΔL sample / displacement component, σ in um");
    c->add_option("--seed", o->seed, "random seed for the noise");
    c->add_option("--probe-log", o->probeLog, "sphere runs: the result file written in the output folder (as the probing "
                                               "program's LOG lines)")
        ->capture_default_str();
    c->add_option("--instrument", o->instrument,
                  "time or angle: write the ball-bar runs as a ball-bar instrument exports them (time- or angle-sampled, "
                  "the passes, directions, overshoot, columns and units of the plan's capture attributes), a simulated "
                  "measurement standing in for the ball bar; no eccentricities.csv (identify fits the files)");
    c->callback([o] { run(*o); });
});

}  // namespace
}  // namespace cnccomp::cli
