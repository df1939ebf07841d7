// cnccomp poses: every motion endpoint of a program in absolute machine coordinates (mm, deg), for checking it.
#include <fstream>
#include <tuple>
#include <iostream>

#include <fmt/format.h>

#include "cli/command.hpp"
#include "cnccomp/error.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "cnccomp/io/text_util.hpp"
#include "postproc/poses.hpp"

namespace cnccomp::cli {
using namespace cnccomp::io;
namespace {

struct Options {
    std::string machine, in, out, dialect = "auto", setup, units, toolTable, tcpOn, tcpOff;
    std::vector<std::string> workOffsets, toolLengths, assume;
    bool rotaryShortest = false;
};

void run(const Options& o) {
    if (!o.out.empty()) checkOutputPath(o.out);  // a folder or a device as --out fails before any work
    postproc::PosesOptions po;
    if (o.dialect != "auto") {
        po.dialect = postproc::parseDialect(o.dialect);
        if (!po.dialect)
            throw InputError("--dialect", 0, fmt::format("unknown dialect '{}' (auto, {})", o.dialect, postproc::dialectNames(postproc::DialectUse::Read)));
    }
    if (!o.setup.empty()) po.setup.readFile(o.setup);
    if (!o.toolTable.empty()) po.setup.readToolTable(o.toolTable);
    for (const auto& [text, name, target] : {std::tuple{&o.tcpOn, "--tcp-on", &po.tcpOnM}, std::tuple{&o.tcpOff, "--tcp-off", &po.tcpOffM}}) {
        if (text->empty()) continue;
        const auto m = postproc::parseMCode(*text);
        if (!m) throw InputError(name, 0, fmt::format("expected an M code such as M428, got '{}'", *text));
        *target = *m;
    }
    for (const auto& w : o.workOffsets) po.setup.addWorkOffset(w);
    for (const auto& l : o.toolLengths) po.setup.addToolLength(l);
    for (const auto& a : o.assume) po.setup.addAssumed(a);
    if (o.units == "inch") po.setup.inchDefault = true;
    else if (!o.units.empty() && o.units != "mm") throw InputError("--units", 0, "expected mm or inch");
    po.rotaryShortest = o.rotaryShortest;
    po.inputName = o.in;
    std::optional<MachineModel> m;
    if (!o.machine.empty()) m = readMachineXml(o.machine);
    const postproc::AxisLayout layout = m ? postproc::AxisLayout::fromMachine(*m) : postproc::AxisLayout::generic();
    std::ifstream in(o.in, std::ios::binary);
    if (!in) throw InputError(o.in, 0, "cannot open the program");
    if (o.out.empty()) {
        postproc::writePoses(layout, in, std::cout, po);
        std::cout.flush();
        return;
    }
    refuseToOverwrite(o.out, {o.in, o.machine, o.setup});
    writeFileAtomically(o.out, [&](std::ostream& out) { postproc::writePoses(layout, in, out, po); });
}

const RegisterCommand reg([](CLI::App& app) {
    auto o = std::make_shared<Options>();
    auto* c = app.add_subcommand("poses", "Print every motion endpoint in machine coordinates: CSV line,motion,X,Y,Z,A,B,C (mm, deg)");
    c->add_option("--in", o->in, "G-code program")->required()->check(CLI::ExistingFile);
    c->add_option("--machine", o->machine, "machine description XML (axes and their kinds); default X Y Z A B C")
        ->check(CLI::ExistingFile);
    c->add_option("--out", o->out, "CSV file to write (default: standard output)");
    c->add_option("--dialect", o->dialect, "auto, rs274ngc (linuxcnc), fanuc, sinumerik, printer")->capture_default_str();
    c->add_option("--work-offset", o->workOffsets, "work offset CODE=x,y,z[,a,b,c] in mm and deg (repeatable)");
    c->add_option("--tool-length", o->toolLengths, "tool length in mm: L or Hn=L for G43 Hn (repeatable)");
    c->add_option("--tool-table", o->toolTable, "LinuxCNC tool table: tool lengths for G43 / G43 Hn")->check(CLI::ExistingFile);
    c->add_option("--tcp-on", o->tcpOn, "M code that switches tool-tip (TCP) programming on, e.g. M428");
    c->add_option("--tcp-off", o->tcpOff, "M code that switches it off, e.g. M429");
    c->add_option("--setup", o->setup, "setup file (see correct --help)")->check(CLI::ExistingFile);
    c->add_option("--assume", o->assume, "positions of axes until the program commands them, e.g. Y=0 (mm, deg; rotary default 0)");
    c->add_option("--units", o->units, "units when the program sets neither G20 nor G21: mm (default) or inch");
    c->add_flag("--rotary-shortest", o->rotaryShortest, "modulo rotary axes: absolute positions reached the shortest way");
    c->callback([o] { run(*o); });
});

}  // namespace
}  // namespace cnccomp::cli
