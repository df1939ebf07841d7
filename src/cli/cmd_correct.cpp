// cnccomp correct: rewrite a G-code program so that the erroneous machine cuts the nominal path.
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>

#include <fmt/format.h>

#include "cli/command.hpp"
#include "cnccomp/error.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "cnccomp/io/text_util.hpp"
#include "postproc/correct_program.hpp"

namespace cnccomp::cli {
using namespace cnccomp::io;
namespace {

struct Options {
    std::string machine, deviations, in, out, dialect = "auto", setup, report, toolTable, tcpOn, tcpOff;
    double tolUm = 1.0;
    int decimals = -1;
    int threads = 0;
    std::vector<std::string> workOffsets, toolLengths, assume;
    bool tipOnly = false, rotaryShortest = false, strict = false, keepPartial = false;
    std::string units;
};

int mCodeOption(const std::string& text, const char* option) {
    if (text.empty()) return -1;
    const auto m = postproc::parseMCode(text);
    if (!m) throw InputError(option, 0, fmt::format("expected an M code such as M428, got '{}'", text));
    return *m;
}

/// Builds the setup from --setup, --tool-table, --work-offset, --tool-length, --units.
postproc::Setup setupOf(const std::string& file, const std::string& toolTable, const std::vector<std::string>& offsets,
                  const std::vector<std::string>& lengths, const std::vector<std::string>& assume,
                  const std::string& units) {
    postproc::Setup s;
    if (!file.empty()) s.readFile(file);
    if (!toolTable.empty()) s.readToolTable(toolTable);
    for (const auto& a : assume) s.addAssumed(a);
    for (const auto& w : offsets) s.addWorkOffset(w);
    for (const auto& l : lengths) s.addToolLength(l);
    if (units == "inch") s.inchDefault = true;
    else if (units == "mm") s.inchDefault = false;
    else if (!units.empty()) throw InputError("--units", 0, fmt::format("expected mm or inch, got '{}'", units));
    return s;
}

std::optional<postproc::Dialect> dialectOf(const std::string& name) {
    if (name == "auto") return std::nullopt;
    // HEIDENHAIN Klartext is also detected from BEGIN PGM.
    const auto d = postproc::parseDialect(name, postproc::DialectUse::Correct);
    if (!d)
        throw InputError("--dialect", 0,
                         fmt::format("unknown dialect '{}' (auto, {})", name, postproc::dialectNames(postproc::DialectUse::Correct)));
    return d;
}

void run(const Options& o) {
    // Outputs first: a folder, a device or a missing folder as --out / --report fails before any work.
    checkOutputPath(o.out);
    if (!o.report.empty()) checkOutputPath(o.report);
    const MachineModel m = readMachineXml(o.machine);
    const DeviationSet d = readDeviationCsv(o.deviations, m);
    refuseToOverwrite(o.out, {o.in, o.machine, o.deviations, o.setup, o.toolTable});
    if (!o.report.empty()) refuseToOverwrite(o.report, {o.in, o.machine, o.deviations, o.setup, o.toolTable, o.out});
    if (std::filesystem::absolute(o.out).lexically_normal() == std::filesystem::absolute(o.in).lexically_normal())
        throw InputError(o.out, 0, "refusing to overwrite the input program");
    if (!(o.tolUm > 0) || !std::isfinite(o.tolUm) || o.tolUm > 1e4)
        throw InputError("--tol-um", 0, "the tolerance must be a positive number of um");
    if (o.decimals < -1 || o.decimals > 12) throw InputError("--decimals", 0, "decimals must be 0..12");
    if (o.threads < 0 || o.threads > 256) throw InputError("--threads", 0, "threads must be 0 (the machine's cores) .. 256");
    postproc::CorrectOptions co;
    co.dialect = dialectOf(o.dialect);
    co.setup = setupOf(o.setup, o.toolTable, o.workOffsets, o.toolLengths, o.assume, o.units);
    co.tcpOnM = mCodeOption(o.tcpOn, "--tcp-on");
    co.tcpOffM = mCodeOption(o.tcpOff, "--tcp-off");
    if (co.tcpOnM >= 0 && co.tcpOnM == co.tcpOffM) throw InputError("--tcp-off", 0, "the same M code as --tcp-on");
    co.rotaryShortest = o.rotaryShortest;
    co.requireToolLength = true;
    co.corrector.toleranceMm = o.tolUm * kUm;
    co.corrector.tipOnly = o.tipOnly;
    co.decimals = o.decimals;
    co.threads = o.threads;
    co.inputName = o.in;
    std::ifstream in(o.in, std::ios::binary);
    if (!in) throw InputError(o.in, 0, "cannot open the program");
    std::error_code ec;
    const auto total = std::filesystem::file_size(o.in, ec);
    const bool bar = ::isatty(STDERR_FILENO) && !ec && total > 0;
    if (bar)
        co.progress = [total](uint64_t done) {
            const int width = 40, filled = static_cast<int>(width * std::min<double>(1.0, double(done) / double(total)));
            std::fprintf(stderr, "\r[%.*s%.*s] %3d%%", filled, "########################################",
                         width - filled, "                                        ",
                         static_cast<int>(100.0 * std::min<double>(1.0, double(done) / double(total))));
            std::fflush(stderr);
        };
    // Both files are written atomically: temporary files beside the targets, renamed only when the correction succeeded.
    std::optional<AtomicFile> report;
    if (!o.report.empty()) {
        report.emplace(o.report);
        report->stream() << "line,kind,message\n";
        co.report = &report->stream();
    }
    postproc::CorrectSummary summary;
    // A correction that does not converge (an end point the solver cannot reach, a move still over the tolerance at
    // the subdivision limit) is a failure: nothing is written unless --keep-partial asks for the partial program.
    bool failed = false;
    try {
        AtomicFile out(o.out);
        summary = postproc::correctProgram(m, d, in, out.stream(), co);
        failed = summary.unconverged + summary.limited > 0;
        if (!failed || o.keepPartial) {
            out.commit();
            if (report) report->commit();
        }
    } catch (...) {
        if (bar) std::fprintf(stderr, "\n");
        throw;
    }
    if (bar) std::fprintf(stderr, "\r%60s\r", "");
    const bool written = !failed || o.keepPartial;
    fmt::print("{} {} for '{}' ({} deviations{}) -> {}\n", written ? "corrected" : "NOT corrected", o.in, m.name,
               std::count(d.present.begin(), d.present.end(), 1), d.values.cwiseAbs().maxCoeff() == 0 ? ", all zero" : "",
               written ? o.out : std::string("nothing written"));
    fmt::print("{}", postproc::formatSummary(summary));
    if (failed) {
        fmt::print(stderr, "cnccomp: the correction did not converge: {} end point(s) not converged, {} move(s) over the "
                           "tolerance at the subdivision limit; {}; exit status 3\n",
                   summary.unconverged, summary.limited,
                   o.keepPartial ? fmt::format("the partial program was written to {} (--keep-partial)", o.out)
                                 : "nothing written (--keep-partial writes the partial program)");
        std::fflush(stdout);
        std::fflush(stderr);
        std::exit(3);
    }
    if (o.strict && summary.uncorrected() > 0) {
        // Scripted use: the files are written (and listed above), the exit status says not everything was corrected.
        fmt::print(stderr, "cnccomp: --strict: {} block(s) left uncorrected (passed through, not converged or over the "
                           "tolerance); exit status 3\n",
                   summary.uncorrected());
        std::fflush(stdout);
        std::fflush(stderr);
        std::exit(3);
    }
}

const RegisterCommand reg([](CLI::App& app) {
    auto o = std::make_shared<Options>();
    auto* c = app.add_subcommand("correct", "Rewrite a G-code program so that the erroneous machine cuts the nominal path");
    c->add_option("--machine", o->machine, "machine description XML")->required()->check(CLI::ExistingFile);
    c->add_option("--deviations", o->deviations, "deviation set CSV (identified or known)")->required()->check(CLI::ExistingFile);
    c->add_option("--in", o->in, "G-code or HEIDENHAIN Klartext program to correct")->required()->check(CLI::ExistingFile);
    c->add_option("--out", o->out, "corrected program to write (never the input)")->required();
    c->add_option("--dialect", o->dialect, "auto, rs274ngc (linuxcnc), fanuc, sinumerik, printer, heidenhain (Klartext: also detected from BEGIN PGM)")->capture_default_str();
    c->add_option("--tol-um", o->tolUm, "largest tool-tip deviation from the nominal path before a move is split, um")
        ->capture_default_str();
    c->add_option("--decimals", o->decimals, "decimals of changed numbers (default: the program's own, at least 4 in mm and deg, 5 in inch)");
    c->add_option("--work-offset", o->workOffsets, "work offset CODE=x,y,z[,a,b,c] in mm and deg, e.g. G54=100,0,-300 (repeatable)");
    c->add_option("--tool-length", o->toolLengths,
                  "tool length in mm: L (default tool point) or Hn=L for G43 Hn (repeatable). Without it: the length a "
                  "test program's header names (cnccomp testprog), else 0 — refused where a rotary move's correction "
                  "depends on it (--tool-length 0 when 0 is meant)");
    c->add_option("--tool-table", o->toolTable, "LinuxCNC tool table (T1 P1 Z12.5 ...): tool lengths for G43 / G43 Hn")
        ->check(CLI::ExistingFile);
    c->add_option("--tcp-on", o->tcpOn, "M code that switches tool-tip (TCP) programming on, e.g. M428 (LinuxCNC trt remap)");
    c->add_option("--tcp-off", o->tcpOff, "M code that switches tool-tip programming off, e.g. M429");
    c->add_flag("--strict", o->strict, "exit status 3 when any block is left uncorrected (passed through, not converged, "
                                       "tolerance not met)");
    c->add_flag("--keep-partial", o->keepPartial,
                "write the program (and --report) even when the correction does not converge (an end point not reached, "
                "a move over the tolerance at the subdivision limit); the exit status is 3 all the same");
    c->add_option("--setup", o->setup, "setup file: lines 'work-offset G54=…', 'tool-length H3=…', 'units mm|inch'")
        ->check(CLI::ExistingFile);
    c->add_option("--assume", o->assume, "positions of axes until the program commands them, e.g. Y=0 (mm, deg; rotary default 0)");
    c->add_option("--units", o->units, "units when the program sets neither G20 nor G21: mm (default) or inch");
    c->add_option("--report", o->report, "write every pass-through and warning as CSV line,kind,message");
    c->add_option("--threads", o->threads,
                  "threads: 1 reads, corrects and writes in one; 2 or more read and solve end points on a second "
                  "(the same output byte for byte); 0 (default): the machine's cores. HEIDENHAIN Klartext runs on one thread")
        ->capture_default_str();
    c->add_flag("--tip-only", o->tipOnly, "correct the tool tip with the linear axes only; rotary commands stay");
    c->add_flag("--rotary-shortest", o->rotaryShortest,
                "modulo rotary axes: absolute positions in [0,360) reached the shortest way (rollover)");
    c->callback([o] { run(*o); });
});

}  // namespace
}  // namespace cnccomp::cli
