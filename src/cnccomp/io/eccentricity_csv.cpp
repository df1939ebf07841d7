#include "cnccomp/io/eccentricity_csv.hpp"

#include <cmath>
#include <ostream>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/csv.hpp"
#include "cnccomp/io/text_util.hpp"

namespace cnccomp::io {

std::vector<EccentricityRow> readEccentricityCsv(const std::string& path) {
    const CsvTable t = readCsv(path);
    const int ct = t.requireColumn("test");
    const int cLB = t.requireColumn("LB_mm"), cRB = t.requireColumn("RB_mm"), cRC = t.requireColumn("RC_mm"),
              cZC = t.requireColumn("ZC_mm");
    const int ce[3] = {t.requireColumn("ex_um"), t.requireColumn("ey_um"), t.requireColumn("ez_um")};
    std::vector<EccentricityRow> rows;
    for (const CsvRow& r : t.rows) {
        EccentricityRow e;
        const std::string& name = t.cell(r, ct);
        const auto test = parseTest(name);
        if (!test)
            throw InputError(path, r.line, fmt::format("unknown test '{}'; expected B-X B-Y B-Z C-radial C-tangential "
                                                       "C-axial C-X C-Y C-Z B-radial B-tangential B-axial", name));
        e.test = *test;
        e.LB = t.number(r, cLB).value_or(0.0);
        e.RB = t.number(r, cRB).value_or(0.0);
        e.RC = t.number(r, cRC).value_or(0.0);
        e.ZC = t.number(r, cZC).value_or(0.0);
        for (int k = 0; k < 3; ++k)
            if (const auto v = t.number(r, ce[k])) e.e[k] = *v * kUm;
        e.source = fmt::format("{}:{}", path, r.line);
        rows.push_back(e);
    }
    if (rows.empty()) throw InputError(path, t.header.line, "no eccentricity rows after the header");
    return rows;
}

void writeEccentricityCsv(std::ostream& o, const std::vector<EccentricityRow>& rows) {
    const auto cell = [](double v) { return std::isfinite(v) ? fmt::format("{:.6f}", v / kUm) : std::string(); };
    o << "test,LB_mm,RB_mm,RC_mm,ZC_mm,ex_um,ey_um,ez_um\n";
    for (const auto& r : rows)
        o << fmt::format("{},{:g},{:g},{:g},{:g},{},{},{}\n", testName(r.test), r.LB, r.RB, r.RC, r.ZC, cell(r.e[0]),
                         cell(r.e[1]), cell(r.e[2]));
}

void writeEccentricityCsv(const std::string& path, const std::vector<EccentricityRow>& rows) {
    writeFileAtomically(path, [&](std::ostream& o) { writeEccentricityCsv(o, rows); });
}

}  // namespace cnccomp::io
