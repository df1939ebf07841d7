// cnccomp compare: an identified deviation set next to a reference (truth) set.
#include <fmt/format.h>

#include "cli/command.hpp"
#include "cli/print.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/machine_xml.hpp"

namespace cnccomp::cli {
namespace {

struct Options {
    std::string machine, truth, estimate;
};

void run(const Options& o) {
    const MachineModel m = readMachineXml(o.machine);
    const DeviationSet truth = readDeviationCsv(o.truth, m);
    const DeviationSet est = readDeviationCsv(o.estimate, m);
    const auto [len, ang] = printDeviations(est, &truth);
    fmt::print("largest difference: {:.4f} um, {:.4f} arcsec\n", len, ang);
}

const RegisterCommand reg([](CLI::App& app) {
    auto o = std::make_shared<Options>();
    auto* c = app.add_subcommand("compare", "Print an identified deviation set next to the truth");
    c->add_option("--machine", o->machine, "machine description XML")->required()->check(CLI::ExistingFile);
    c->add_option("--truth", o->truth, "reference deviation CSV")->required()->check(CLI::ExistingFile);
    c->add_option("--estimate", o->estimate, "identified deviation CSV")->required()->check(CLI::ExistingFile);
    c->callback([o] { run(*o); });
});

}  // namespace
}  // namespace cnccomp::cli
