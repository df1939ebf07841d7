#include "cnccomp/io/trace_csv.hpp"

#include <ostream>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/csv.hpp"
#include "cnccomp/io/text_util.hpp"

namespace cnccomp {

BallbarTrace readTraceCsv(const std::string& path) {
    const CsvTable t = readCsv(path);
    const int ca = t.requireColumn("angle_deg"), cl = t.requireColumn("dL_um");
    BallbarTrace tr;
    for (const CsvRow& r : t.rows) {
        tr.angleDeg.push_back(t.requireNumber(r, ca));
        tr.dL.push_back(t.requireNumber(r, cl) * kUm);
    }
    if (tr.dL.size() < 3) throw InputError(path, 0, "a trace needs at least three samples");
    return tr;
}

void writeTraceCsv(const std::string& path, const BallbarTrace& trace) {
    writeFileAtomically(path, [&](std::ostream& o) {
        o << "angle_deg,dL_um\n";
        for (size_t i = 0; i < trace.dL.size(); ++i) o << fmt::format("{:.6f},{:.6f}\n", trace.angleDeg[i], trace.dL[i] / kUm);
    });
}

}  // namespace cnccomp

namespace cnccomp {
std::vector<BallbarTrace> readRunTraces(const std::string& dir, const std::vector<BallbarRun>& runs) {
    std::vector<BallbarTrace> out;
    for (const BallbarRun& r : runs) out.push_back(readTraceCsv(dir + "/" + r.name + ".csv"));
    return out;
}
}  // namespace cnccomp
