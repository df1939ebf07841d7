// cnccomp testprog: the NC programs that make a plan's ball-bar / R-test / DBB5 measurements, one per run plus an index.
#include <filesystem>

#include <fmt/format.h>

#include "cli/command.hpp"
#include "cnccomp/error.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "cnccomp/io/output_set.hpp"
#include "postproc/testprog/probe_program.hpp"
#include "postproc/testprog/test_program.hpp"

namespace cnccomp::cli {
using namespace cnccomp::io;
using namespace cnccomp::measurement;
namespace {

struct Options {
    std::string machine, plan, dialect = "linuxcnc", out, probeLog = "cnccomp-probe.txt";
    postproc::testprog::TestProgramOptions program;
};

void run(Options o) {
    const auto d = postproc::parseDialect(o.dialect, postproc::DialectUse::Write);
    if (!d) throw InputError("--dialect", 0, fmt::format("unknown dialect '{}' ({})", o.dialect, postproc::dialectNames(postproc::DialectUse::Write)));
    o.program.dialect = *d;
    const MachineModel m = readMachineXml(o.machine);
    const MeasurementPlan plan = readPlanXml(o.plan);
    o.program.machineFile = std::filesystem::path(o.machine).filename().string();
    o.program.planFile = std::filesystem::path(o.plan).filename().string();
    if (!plan.sphereRuns.empty()) {
        if (plan.runCount() != plan.sphereRuns.size())
            throw ModelError("the plan has sphere runs and other runs: put the <sphere> runs in a plan of their own");
        postproc::testprog::ProbeProgramOptions po;
        po.dialect = *d;
        po.log = o.probeLog;
        po.decimals = o.program.decimals;
        po.machineFile = o.program.machineFile;
        po.planFile = o.program.planFile;
        const postproc::testprog::ProbeProgram p = postproc::testprog::makeProbeProgram(m, plan, po);
        OutputSet staged({o.machine, o.plan});
        staged.makeFolder(o.out);
        for (const postproc::testprog::ProbeProgramFile& f : p.files) {
            const std::string text = f.text;
            staged.add(OutputSet::fileIn(o.out, f.file, o.plan), [text](std::ostream& s) { s << text; });
        }
        staged.commit();
        fmt::print("probing program for '{}' ({}) in {}: {} poses, {} touches; it writes {}\n", m.name, o.dialect, o.out,
                   p.poses, p.touches, o.probeLog);
        for (const postproc::testprog::ProbeProgramFile& f : p.files) fmt::print("  {}\n", f.file);
        return;
    }
    if (o.probeLog != "cnccomp-probe.txt") throw ModelError("--probe-log applies to plans with sphere runs");
    const postproc::testprog::TestProgramSet set = postproc::testprog::makeTestPrograms(m, plan, o.program);
    postproc::testprog::writeTestPrograms(set, o.out, {o.machine, o.plan});
    fmt::print("{} test programs for '{}' ({}) in {}:\n", set.programs.size(), m.name, o.dialect, o.out);
    for (const postproc::testprog::TestProgram& p : set.programs)
        fmt::print("  {:<40} {:<18} {:<18} {:>6} samples, first {}, {}{}\n", p.file, p.run, postproc::testprog::runKindName(p.kind),
                   p.samples, p.firstPass, p.arcs ? "circular blocks" : "straight blocks",
                   p.overshootStart < o.program.overshootDeg || p.overshootEnd < o.program.overshootDeg
                       ? fmt::format(", overshoot {:g}/{:g} deg", p.overshootStart, p.overshootEnd)
                       : "");
    fmt::print("  {}\n", set.indexFile);
}

const RegisterCommand reg([](CLI::App& app) {
    auto o = std::make_shared<Options>();
    auto* c = app.add_subcommand("testprog",
                                 "Write the NC programs that make the plan's measurements (one per run, plus index.csv).\n"
                                 "Each program: setup comments, approach, setup stop, feed-in overshoot, the sweep CW then CCW,\n"
                                 "feed-out overshoot, retract; positions in the controller's machine coordinates.\n"
                                 "Exit status: 0 written; 2 bad input or a run the machine cannot make (nothing written).");
    c->add_option("--machine", o->machine, "machine description XML")->required()->check(CLI::ExistingFile);
    c->add_option("--plan", o->plan, "measurement plan XML")->required()->check(CLI::ExistingFile);
    c->add_option("--dialect", o->dialect, "linuxcnc (rs274ngc), fanuc, sinumerik, heidenhain (Klartext)")->capture_default_str();
    c->add_option("--out", o->out, "output folder (created if missing)")->required();
    c->add_option("--feed", o->program.feed, "feed on the sweep, mm/min")->capture_default_str();
    c->add_option("--approach-feed", o->program.approachFeed, "feed onto the setup and start poses, mm/min")->capture_default_str();
    c->add_option("--overshoot", o->program.overshootDeg, "feed-in / feed-out overshoot, deg of the sweep (shortened at the travel ends)")
        ->capture_default_str();
    c->add_option("--clearance", o->program.clearance, "retract along the tool axis, mm")->capture_default_str();
    c->add_option("--dwell", o->program.dwellSeconds, "R-test: dwell at each pose, s")->capture_default_str();
    c->add_option("--decimals", o->program.decimals, "digits after the point")->capture_default_str();
    c->add_option("--probe-log", o->probeLog, "sphere plans: the result file the probing program writes")
        ->capture_default_str();
    c->callback([o] { run(*o); });
});

}  // namespace
}  // namespace cnccomp::cli
