// cnccomp compare: an identified deviation set next to a reference (truth) set.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "cli/command.hpp"
#include "cli/print.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/machine_xml.hpp"

namespace cnccomp::cli {
using namespace cnccomp::io;
namespace {

struct Options {
    std::string machine, truth, estimate;
};

void run(const Options& o) {
    const MachineModel m = readMachineXml(o.machine);
    const DeviationSet truth = readDeviationCsv(o.truth, m);
    const DeviationSet est = readDeviationCsv(o.estimate, m);
    auto [len, ang] = printDeviations(est, &truth);
    // Deviations on one side only: never drop them silently.
    std::vector<std::string> missing, extra;
    for (size_t i = 0; i < m.deviations.size(); ++i) {
        const DeviationDef& d = m.deviations[i];
        const std::string label = d.alias.empty() ? d.name : fmt::format("{} ({})", d.name, d.alias);
        if (truth.present[i] && !est.present[i]) missing.push_back(label);
        if (!truth.present[i] && est.present[i]) extra.push_back(label);
    }
    // Deviations neither file lists still have values: a file's names fix the rest (zero under ISO names, or under the
    // aliases when every row uses an alias; deviation_csv.hpp), and an ISO name and its alias differ in meaning (an ISO
    // location error is measured against the standard's reference axis). Compare the geometry the two files imply.
    int implied = 0;
    bool header = false;
    for (size_t i = 0; i < m.deviations.size(); ++i) {
        const DeviationDef& d = m.deviations[i];
        if (d.kind != DeviationKind::Location || truth.present[i] || est.present[i]) continue;
        const int index = static_cast<int>(i);
        const double scale = d.isAngle() ? 1.0 / kArcsec : 1.0 / kUm;
        const double e = est.isoValue(index) * scale, t = truth.isoValue(index) * scale;
        if (std::abs(e - t) < 5e-7) continue;
        if (!header)
            fmt::print("implied by the names the files use (listed in neither file; ISO values; compared):\n");
        header = true;
        ++implied;
        (d.isAngle() ? ang : len) = std::max(d.isAngle() ? ang : len, std::abs(e - t));
        fmt::print("{:<8} {:<6} {:12.4f} {:12.4f} {:10.4f}  {}\n", d.name, d.alias, e, t, e - t,
                   d.isAngle() ? "arcsec" : "um");
    }
    // Reversal values (B<axis>, um): compared where both sets have one, listed where one has.
    bool reversalHeader = false;
    for (int a = 0; a < m.axisCount(); ++a) {
        const size_t k = static_cast<size_t>(a);
        const std::string name = "B" + m.axisNames[k];
        if (truth.reversalPresent[k] && !est.reversalPresent[k]) missing.push_back(name);
        if (!truth.reversalPresent[k] && est.reversalPresent[k]) extra.push_back(name);
        if (!truth.reversalPresent[k] || !est.reversalPresent[k]) continue;
        if (!reversalHeader) fmt::print("reversal values (ISO 230-2 mean reversal; estimate, truth, difference):\n");
        reversalHeader = true;
        const double e = est.reversal[k] / kUm, t = truth.reversal[k] / kUm;
        len = std::max(len, std::abs(e - t));
        fmt::print("{:<8} {:<6} {:12.4f} {:12.4f} {:10.4f}  um\n", name, "", e, t, e - t);
    }
    const auto both = std::count_if(m.deviations.begin(), m.deviations.end(), [&](const DeviationDef& d) {
        const int i = static_cast<int>(&d - m.deviations.data());
        return truth.present[i] && est.present[i];
    });
    fmt::print("largest difference: {:.4f} um, {:.4f} arcsec (over the {} deviations in both sets and {} that the files' "
               "names imply)\n",
               len, ang, both, implied);
    if (implied > 0)
        fmt::print("the two files imply different values for {} deviation(s) neither lists: the machines differ there\n",
                   implied);
    if (!missing.empty())
        fmt::print("missing from the estimate ({} of the truth's deviations, not compared): {}\n", missing.size(),
                   fmt::join(missing, ", "));
    if (!extra.empty())
        fmt::print("in the estimate but not in the truth (not compared): {}\n", fmt::join(extra, ", "));
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
