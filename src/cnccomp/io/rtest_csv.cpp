#include "cnccomp/io/rtest_csv.hpp"

#include <cmath>
#include <ostream>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/csv.hpp"
#include "cnccomp/io/text_util.hpp"

namespace cnccomp::io {
using namespace cnccomp::identification;
using namespace cnccomp::measurement;

namespace {

double axisUnit(const MachineModel& m, int i) { return m.axisLink(i).kind == AxisKind::Rotary ? kDeg : 1.0; }

struct Parsed {
    RtestTrace trace;
    std::vector<int> lines;
};

Parsed parse(const std::string& path, const MachineModel& m) {
    const CsvTable t = readCsv(path);
    std::vector<int> axisCols;
    for (int i = 0; i < m.axisCount(); ++i) axisCols.push_back(t.requireColumn(axisColumn(m, i)));
    const int cx = t.requireColumn("dx_um"), cy = t.requireColumn("dy_um"), cz = t.requireColumn("dz_um");
    Parsed p;
    for (const CsvRow& r : t.rows) {
        AxisVector q(m.axisCount());
        for (int i = 0; i < m.axisCount(); ++i) q[i] = t.requireNumber(r, axisCols[static_cast<size_t>(i)]) * axisUnit(m, i);
        p.trace.commands.push_back(q);
        p.trace.d.emplace_back(t.requireNumber(r, cx) * kUm, t.requireNumber(r, cy) * kUm, t.requireNumber(r, cz) * kUm);
        p.lines.push_back(r.line);
    }
    if (p.trace.d.size() < 3) throw InputError(path, 0, "an R-test trace needs at least three poses");
    return p;
}

}  // namespace

RtestTrace readRtestCsv(const std::string& path, const MachineModel& m) { return parse(path, m).trace; }

void writeRtestCsv(std::ostream& o, const MachineModel& m, const RtestTrace& trace) {
    if (trace.commands.size() != trace.d.size()) throw ModelError("R-test trace: poses and displacements differ");
    o << "pose";
    for (int i = 0; i < m.axisCount(); ++i) o << ',' << axisColumn(m, i);
    o << ",dx_um,dy_um,dz_um\n";
    for (size_t k = 0; k < trace.d.size(); ++k) {
        o << k + 1;
        for (int i = 0; i < m.axisCount(); ++i) o << fmt::format(",{:.9f}", trace.commands[k][i] / axisUnit(m, i));
        o << fmt::format(",{:.6f},{:.6f},{:.6f}\n", trace.d[k].x() / kUm, trace.d[k].y() / kUm, trace.d[k].z() / kUm);
    }
}

void writeRtestCsv(const std::string& path, const MachineModel& m, const RtestTrace& trace) {
    if (trace.commands.size() != trace.d.size()) throw ModelError("R-test trace: poses and displacements differ");
    writeFileAtomically(path, [&](std::ostream& o) { writeRtestCsv(o, m, trace); });
}

std::vector<RtestTrace> readRtestTraces(const std::string& dir, const MachineModel& m, const std::vector<RtestRun>& runs) {
    std::vector<RtestTrace> out;
    for (const RtestRun& run : runs) {
        const std::string path = dir + "/" + run.name + ".csv";
        Parsed p = parse(path, m);
        const std::vector<AxisVector> plan = rtestCommands(m, run);
        if (plan.size() != p.trace.d.size())
            throw InputError(path, 0, fmt::format("{} poses, but the plan's run '{}' has {}", p.trace.d.size(), run.name, plan.size()));
        for (size_t k = 0; k < plan.size(); ++k)
            for (int i = 0; i < m.axisCount(); ++i)
                if (std::abs(plan[k][i] - p.trace.commands[k][i]) / axisUnit(m, i) > 1e-5)
                    throw InputError(path, p.lines[k],
                                     fmt::format("{} = {:.6f} differs from the plan's pose {} ({:.6f})", axisColumn(m, i),
                                                 p.trace.commands[k][i] / axisUnit(m, i), k + 1, plan[k][i] / axisUnit(m, i)));
        p.trace.commands = plan;
        out.push_back(std::move(p.trace));
    }
    return out;
}

}  // namespace cnccomp::io
