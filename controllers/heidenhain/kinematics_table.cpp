#include "controllers/heidenhain/kinematics_table.hpp"

#include "controllers/common/set_backlash.hpp"
#include "controllers/heidenhain/laser_com.hpp"

#include <cctype>
#include <cmath>
#include <map>
#include <optional>
#include <set>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/text_util.hpp"
#include "controllers/common/axis_table.hpp"
#include "controllers/common/header.hpp"
#include "controllers/heidenhain/tnc_table.hpp"

namespace cnccomp::controllers::heidenhain {
using namespace cnccomp::controllers::common;
using namespace cnccomp::io;

Vec3 letterDirection(std::string_view a) {
    if (a == "X" || a == "U" || a == "A") return Vec3::UnitX();
    if (a == "Y" || a == "V" || a == "B") return Vec3::UnitY();
    if (a == "Z" || a == "W" || a == "C") return Vec3::UnitZ();
    return Vec3::Zero();
}

namespace {

constexpr const char* kLetters[6] = {"X", "Y", "Z", "A", "B", "C"};
const std::vector<std::string> kColumns = {"NR", "KEY", "AXIS", "COORD", "FILE", "DOC", "COMPTAB"};

std::string fileStem(const std::string& machine) {
    std::string s;
    for (char c : machine) s += std::isalnum(static_cast<unsigned char>(c)) ? static_cast<char>(std::toupper(c)) : '_';
    return s.empty() ? "MACHINE" : s;
}

/// One .COM table: one axis, shared positions, one column per error component.
struct ComFile {
    int axis = -1;
    std::string name;
    std::vector<double> positions;  // file units (mm / deg)
    std::map<int, std::vector<double>> columns;  // component → values in file units (mm / deg), ISO errors
    std::map<int, std::vector<std::string>> sources;
};

struct RowWriter {
    TncTable& t;
    int transforms = 0, comptabs = 0, axes = 0;
    void add(const std::string& key, const std::string& axis, const std::string& coord, const std::string& doc,
             const std::string& comptab = "") {
        t.rows.push_back({std::to_string(t.rows.size()), key, axis, coord, "", doc, comptab});
        if (key == "Trans" || key == "MachAxis") ++transforms;
        if (key == "MachAxis") ++axes;
        if (!comptab.empty()) ++comptabs;
    }
    /// Rows for T(t)·Rx(a)·Ry(b)·Rz(c); components listed in `forced` are written even when zero.
    void pose(const Pose& p, const std::set<int>& forced, const std::string& doc) {
        const Vec3 t3 = p.translation();
        const Vec3 abc = xyzAngles(p.linear());
        for (int k = 0; k < 3; ++k)
            if (t3[k] != 0.0 || forced.count(k)) add("Trans", kLetters[k], fixed(t3[k], 9), doc);
        for (int k = 0; k < 3; ++k)
            if (std::abs(abc[k]) > 1e-15 || forced.count(3 + k)) add("Trans", kLetters[3 + k], fixed(abc[k] / kDeg, 10), doc);
    }
};

std::string names(const std::vector<std::string>& v) {
    std::string s;
    for (const auto& x : v) s += (s.empty() ? "" : ",") + x;
    return s;
}

}  // namespace

EmitResult emitFiles(const EmitRequest& request, const Options& o) {
    const MachineModel& m = request.machine;
    const DeviationSet& d = request.deviations;
    d.requireMachine(m);
    if (!d.values.allFinite()) throw ModelError("the deviation set holds a value that is not a finite number");
    for (int a = 0; a < m.axisCount(); ++a) {
        const Link& l = m.axisLink(a);
        const Vec3 dir = letterDirection(l.name);
        if (dir.isZero())
            throw ModelError(fmt::format("heidenhain-tnc: axis '{}' has no TNC axis letter (X Y Z U V W A B C)", l.name));
        if ((l.direction - dir).norm() > 1e-12)
            throw ModelError(fmt::format("heidenhain-tnc: axis {} moves along ({:g} {:g} {:g}) in its frame, but a TNC "
                                         "MachAxis {} moves along +{}",
                                         l.name, l.direction.x(), l.direction.y(), l.direction.z(), l.name,
                                         dir.x() > 0 ? "X" : dir.y() > 0 ? "Y" : "Z"));
    }
    int toolAxis = -1;
    for (int k = 0; k < 3; ++k)
        if ((m.toolDirection + Vec3::Unit(k)).norm() < 1e-12) toolAxis = k;
    if (toolAxis < 0) throw ModelError("heidenhain-tnc: the tool must point along -X, -Y or -Z of the tool frame (ToolAxis)");

    EmitResult r;
    // Component errors → .COM columns.
    std::map<int, ComFile> com;  // by machine axis
    std::map<int, std::string> why;  // deviation index → reason not compensated
    for (int a = 0; a < m.axisCount(); ++a) {
        const Link& l = m.axisLink(a);
        std::vector<int> defs;
        for (size_t di = 0; di < m.deviations.size(); ++di) {
            const DeviationDef& def = m.deviations[di];
            if (d.present[di] && def.kind == DeviationKind::Component && m.chain(def.side).links[def.link].axisIndex == a)
                defs.push_back(static_cast<int>(di));
        }
        if (defs.empty()) continue;
        const double scale = positionScale(l);
        // Positions: the defs' own table nodes when they share them, else an equidistant grid over the travel.
        std::vector<double> pos;
        const auto& first = m.deviations[defs[0]].basis;
        bool shared = first.type == ComponentBasis::Type::Table;
        for (int di : defs) shared = shared && m.deviations[di].basis.type == ComponentBasis::Type::Table &&
                                     m.deviations[di].basis.nodes == first.nodes;
        const int capacity = o.maxCompRows - (l.modulo ? 1 : 0);
        if (shared && static_cast<int>(first.nodes.size()) <= capacity) {
            for (double n : first.nodes) pos.push_back((n - l.machineZero) * scale);  // machine positions
            if (l.modulo) pos.push_back(pos.front() + 360.0);
        } else {
            try {
                const EquidistantTable g = gridOverTravel(l, o.maxCompRows);
                for (size_t n = 0; n < g.values.size(); ++n) pos.push_back(g.min + g.step * n);
            } catch (const ModelError& e) {
                for (int di : defs) why[di] = e.what();
                continue;
            }
        }
        ComFile f;
        f.axis = a;
        f.name = l.name + ".COM";
        f.positions = pos;
        for (int di : defs) {
            const DeviationDef& def = m.deviations[di];
            const double* coef = d.values.data() + def.offset;
            const auto err = [&](double q) { return def.basis.evaluate(q, coef, l.modulo); };
            if (l.modulo && std::abs(err(commandOf(l, pos.front())) - err(commandOf(l, pos.back()))) > 1e-9) {
                why[di] = "not periodic over one revolution: a modulo table must close on itself";
                continue;
            }
            auto& col = f.columns[def.component];
            col.resize(pos.size(), 0.0);
            for (size_t n = 0; n < pos.size(); ++n) col[n] += err(commandOf(l, pos[n])) / (def.isAngle() ? kDeg : 1.0);
            if (l.modulo) col.back() = col.front();  // exact closure
            f.sources[def.component].push_back(def.name);
        }
        if (!f.columns.empty()) com.emplace(a, std::move(f));
    }

    // Coverage.
    for (size_t di = 0; di < m.deviations.size(); ++di) {
        if (!d.present[di]) continue;
        const DeviationDef& def = m.deviations[di];
        const Link& l = m.chain(def.side).links[def.link];
        const char* side = def.side == Side::Tool ? "tool side" : "table side";
        if (def.kind == DeviationKind::Location) {
            r.compensated.push_back({def.name, l.axisIndex >= 0
                                                   ? fmt::format("Trans {} row beside MachAxis {} ({})", kLetters[def.component], l.name, side)
                                                   : fmt::format("Trans {} row of {} ({})", kLetters[def.component], l.name, side)});
        } else if (why.count(static_cast<int>(di))) {
            r.notCompensated.push_back({def.name, why[static_cast<int>(di)]});
        } else {
            r.compensated.push_back({def.name, fmt::format("{}.COM column C{} (KinematicsComp, {})", l.name, def.component + 1, side)});
        }
    }

    // The kinematics description: tool reference point → tool side → MachBase → table.
    TncTable kin;
    kin.name = fileStem(m.name) + ".TAB";
    kin.columns = kColumns;
    RowWriter w{kin};
    w.add("ToolAxis", kLetters[toolAxis], "", "tool axis");
    const auto locationInfo = [&](Side s, int link) {
        std::set<int> forced;
        std::vector<std::string> n;
        for (size_t di = 0; di < m.deviations.size(); ++di) {
            const DeviationDef& def = m.deviations[di];
            if (d.present[di] && def.kind == DeviationKind::Location && def.side == s && def.link == link) {
                forced.insert(def.component);
                n.push_back(def.name);
            }
        }
        return std::make_pair(forced, names(n));
    };
    const auto compRows = [&](const Link& l, bool tool) {
        const auto it = com.find(l.axisIndex);
        if (it == com.end()) return;
        std::vector<int> comps;
        for (const auto& [c, v] : it->second.columns) comps.push_back(c);
        if (tool) std::reverse(comps.begin(), comps.end());
        for (int c : comps)
            w.add("Trans", kLetters[c], fixed(0.0, 9), names(it->second.sources[c]), fmt::format("{}:C{}", it->second.name, c + 1));
    };
    // The TNC counts an axis from its machine datum: a Trans row along the axis' own letter carries the description's
    // motion up to there (inverted on the tool side, which the rows walk from the tool to the base).
    const auto machineZero = [&](const Link& l, bool tool) {
        if (l.machineZero == 0.0) return;
        const double v = (tool ? -1.0 : 1.0) * l.machineZero;
        int k = 0;
        letterDirection(l.name).cwiseAbs().maxCoeff(&k);
        if (l.kind == AxisKind::Linear) w.add("Trans", kLetters[k], fixed(v, 9), "machine datum");
        else w.add("Trans", kLetters[3 + k], fixed(v / kDeg, 10), "machine datum");
    };
    const Chain& tc = m.tool;
    for (int i = static_cast<int>(tc.links.size()) - 1; i >= 0; --i) {
        const Link& l = tc.links[i];
        if (l.axisIndex >= 0) {
            compRows(l, true);
            w.add("MachAxis", l.name, "", "axis");
            machineZero(l, true);
        }
        const auto [forced, doc] = locationInfo(Side::Tool, i);
        w.pose(errorTransform(linkLocationError(m, d.values, Side::Tool, i)).inverse(Eigen::Isometry), forced,
               doc.empty() ? "" : "inv:" + doc);
        w.pose(l.placement.inverse(Eigen::Isometry), {}, "inv:nominal");
    }
    w.add("MachBase", "", "", "machine base");
    const Chain& wc = m.workpiece;
    for (int i = 0; i < static_cast<int>(wc.links.size()); ++i) {
        const Link& l = wc.links[i];
        w.pose(l.placement, {}, "nominal");
        const auto [forced, doc] = locationInfo(Side::Workpiece, i);
        w.pose(errorTransform(linkLocationError(m, d.values, Side::Workpiece, i)), forced, doc);
        if (l.axisIndex >= 0) {
            machineZero(l, false);
            w.add("MachAxis", l.name, "", "axis");
            compRows(l, false);
        }
    }
    if (w.transforms > o.maxTransformRows)
        throw ModelError(fmt::format("heidenhain-tnc: the kinematics description needs {} Trans/MachAxis rows; the TNC "
                                     "takes {}",
                                     w.transforms, o.maxTransformRows));
    // iTNC 530 HSCI technical manual 07/2013 p.686: the MachAxis rows count against the COMPTAB entries.
    if (w.comptabs + w.axes > o.maxCompEntries)
        throw ModelError(fmt::format("heidenhain-tnc: {} COMPTAB entries and {} MachAxis rows need {} entries; the TNC takes {}",
                                     w.comptabs, w.axes, w.comptabs + w.axes, o.maxCompEntries));

    // Reversal values → MP710 backlash (the laser route's line, laser_com.hpp; set_backlash.hpp).
    std::string backlash;
    for (const AxisBacklash& b : backlashOfSet(request)) {
        const int index = tncAxisIndex(b.name);
        if (index < 0) continue;  // left NOT compensated by the header (reversalsNotHeld)
        backlash += mp710Line(index, b.backlashUm * 1e-3) + "\n";
        r.compensated.push_back({"B" + b.name, fmt::format("{} = -B{} (backlash, mm) in {}", mp710Line(index, b.backlashUm * 1e-3),
                                                           b.name, kBacklashFile)});
    }
    std::vector<std::string> notes = {
        "for the iTNC 530 (HSCI technical manual 07/2013, KinematicsComp): the TNC 640 and TNC7 keep the kinematics in "
        "the machine configuration (kinematics editor), not in a .TAB description: these files do not load there",
        "units: mm and degrees; KinematicsComp tables interpolated linearly between AXISPOS rows",
        frameNote(m),
        "absolute values: the description replaces the machine's kinematics (Trans rows in machine coordinates, a "
        "'machine datum' row where an axis counts from elsewhere); AXISPOS are machine positions; nothing is a delta",
        fmt::format("{} Trans+MachAxis rows (50 allowed), {} COMPTAB entries + {} MachAxis rows (100 allowed, p.686)",
                    w.transforms, w.comptabs, w.axes),
        "rows are a transformation chain from the tool reference point to the table: tool-side rows (before "
        "MachBase) are the inverse transforms, so their .COM columns hold -error [G: confirm with KinematicsDesign]",
        "location errors are not wrapped back after their MachAxis: the workpiece datum follows the measured axis "
        "lines as in the deviation set",
    };
    const std::string comment = formatHeader(
        makeHeaderInfo(request, "HEIDENHAIN TNC (kinematics description + KinematicsComp .COM tables)", r, notes), "; ");
    r.files.push_back({kin.name, formatTncTable(kin, comment)});
    for (const auto& [a, f] : com) {
        const bool tool = m.axisSide(a) == Side::Tool;
        TncTable t;
        t.name = f.name;
        t.columns = {"NR", "AXISPOS"};
        for (const auto& [c, v] : f.columns) t.columns.push_back(fmt::format("C{}", c + 1));
        if (static_cast<int>(f.positions.size()) > o.maxCompRows)
            throw ModelError(fmt::format("heidenhain-tnc: {} needs {} rows; a .COM table takes {}", f.name,
                                         f.positions.size(), o.maxCompRows));
        for (size_t n = 0; n < f.positions.size(); ++n) {
            std::vector<std::string> row = {std::to_string(n), fixed(f.positions[n], 6)};
            for (const auto& [c, v] : f.columns) row.push_back(fixed(tool ? -v[n] : v[n], c >= 3 ? 10 : 9));
            t.rows.push_back(std::move(row));
        }
        r.files.push_back({t.name, formatTncTable(t, comment)});
    }
    if (!backlash.empty())
        r.files.push_back({kBacklashFile, comment +
                                              "; MP710.x backlash compensation (mm) = -B<axis>, the deviation set's reversal value: "
                                              "positive when the encoder reading is ahead of the table (lost motion; TNC 426/430 "
                                              "Technical Manual 6.4.1); TNC 640 / TNC7: MP_backLash of the axis [G: file syntax]\n" +
                                              backlash});
    return r;
}

namespace {

struct WalkRow {
    int line = 0;
    bool axis = false;
    int component = 0;   // Trans: 0..5
    double value = 0;    // Trans: mm or rad
    int machineAxis = -1;
    std::string com;     // COMPTAB file
    int column = 0;      // COMPTAB column number (1..6)
};

Pose transPose(int component, double v) {
    Pose p = Pose::Identity();
    if (component < 3) p.translation()[component] = v;
    else p.linear() = axisRotation(Vec3::Unit(component - 3), v);
    return p;
}

}  // namespace

ParsedKinematics parseFiles(const MachineModel& m, const std::vector<OutputFile>& files) {
    const OutputFile* kinFile = nullptr;
    std::map<std::string, const OutputFile*> comFiles;
    for (const OutputFile& f : files) {
        if (f.name.ends_with(".TAB")) {
            if (kinFile) throw InputError(f.name, 0, fmt::format("two kinematics descriptions ({} and {})", kinFile->name, f.name));
            kinFile = &f;
        } else if (f.name.ends_with(".COM")) {
            comFiles[f.name] = &f;
        } else if (f.name == kBacklashFile) {
            continue;  // read by the backend's apply (heidenhain_backend.cpp)
        } else {
            throw InputError(f.name, 0, "not a heidenhain-tnc file (expected a .TAB kinematics description or .COM tables)");
        }
    }
    if (!kinFile) throw InputError("<heidenhain-tnc files>", 0, "no kinematics description (.TAB)");
    const std::string& path = kinFile->name;
    const TncTable t = parseTncTable(path, kinFile->content, {"NR", "KEY", "AXIS", "COORD"});
    const int cKey = t.column("KEY"), cAxis = t.column("AXIS"), cCoord = t.column("COORD"), cComp = t.column("COMPTAB");
    std::vector<WalkRow> toolRows, wpRows;
    bool base = false;
    for (size_t i = 0; i < t.rows.size(); ++i) {
        const int line = t.lines[i];
        const std::string& key = t.cell(i, cKey);
        const std::string& ax = t.cell(i, cAxis);
        const std::string& coord = t.cell(i, cCoord);
        if (key == "ToolAxis") {
            const Vec3 dir = letterDirection(ax);
            if (dir.isZero() || ax.size() != 1 || ax[0] > 'Z' || ax[0] < 'X')
                throw InputError(path, line, fmt::format("ToolAxis '{}': expected X, Y or Z", ax));
            if ((m.toolDirection + dir).norm() > 1e-9)
                throw InputError(path, line, fmt::format("ToolAxis {} does not match the machine's tool direction", ax));
            continue;
        }
        if (key == "CMO") continue;
        if (key == "MachBase") {
            if (base) throw InputError(path, line, "MachBase appears twice");
            base = true;
            continue;
        }
        WalkRow w;
        w.line = line;
        if (key == "MachAxis") {
            w.axis = true;
            w.machineAxis = m.axisIndex(ax);
            if (w.machineAxis < 0) throw InputError(path, line, fmt::format("MachAxis '{}': machine '{}' has no such axis", ax, m.name));
            if (letterDirection(ax).isZero()) throw InputError(path, line, fmt::format("MachAxis '{}': not a TNC axis letter", ax));
            if (!coord.empty()) throw InputError(path, line, "a MachAxis row takes no COORD");
        } else if (key == "Trans") {
            w.component = -1;
            for (int k = 0; k < 6; ++k)
                if (ax == kLetters[k]) w.component = k;
            if (w.component < 0) throw InputError(path, line, fmt::format("Trans AXIS '{}': expected X, Y, Z, A, B or C", ax));
            const auto v = parseNumber(coord);
            if (!v || !std::isfinite(*v)) throw InputError(path, line, fmt::format("Trans COORD '{}' is not a number", coord));
            w.value = w.component < 3 ? *v : *v * kDeg;
            const std::string& comp = t.cell(i, cComp);
            if (!comp.empty()) {
                const size_t colon = comp.rfind(":C");
                const std::optional<double> k = colon == std::string::npos ? std::optional<double>{} : parseNumber(comp.substr(colon + 2));
                if (!k || *k < 1 || *k > 6 || *k != std::floor(*k))
                    throw InputError(path, line, fmt::format("COMPTAB '{}': expected FILE.COM:Ck with k = 1..6", comp));
                w.com = comp.substr(0, colon);
                w.column = static_cast<int>(*k);
                if (w.column != w.component + 1)
                    throw InputError(path, line, fmt::format("COMPTAB column C{} holds {} errors but the row is Trans {}",
                                                             w.column, kLetters[w.column - 1], ax));
                if (*v != 0.0) throw InputError(path, line, "a COMPTAB row's COORD must be 0 (the table holds the value)");
                if (!comFiles.count(w.com)) throw InputError(path, line, fmt::format("COMPTAB names '{}', which is not among the files", w.com));
            }
        } else {
            throw InputError(path, line, fmt::format("KEY '{}' is not read (expected Trans, MachAxis, MachBase, ToolAxis or CMO)", key));
        }
        (base ? wpRows : toolRows).push_back(w);
    }
    if (!base) throw InputError(path, t.lines.empty() ? 2 : t.lines.back(), "missing MachBase row");

    ParsedKinematics out;
    std::map<std::string, TncTable> parsedCom;
    std::set<std::pair<int, int>> seen;
    const auto attach = [&](const WalkRow& row, int axis, bool tool) {
        if (!seen.insert({axis, row.component}).second)
            throw InputError(path, row.line, fmt::format("second table for the {} error of axis {}", kLetters[row.component], m.axisNames[axis]));
        auto it = parsedCom.find(row.com);
        if (it == parsedCom.end())
            it = parsedCom.emplace(row.com, parseTncTable(row.com, comFiles[row.com]->content, {"NR", "AXISPOS"})).first;
        const TncTable& c = it->second;
        const int col = c.column(fmt::format("C{}", row.column));
        if (col < 0) throw InputError(row.com, 2, fmt::format("missing column C{} named in {} line {}", row.column, path, row.line));
        const Link& l = m.axisLink(axis);
        const double scale = positionScale(l);
        ComponentTable ct;
        ct.axis = axis;
        ct.component = row.component;
        const int cPos = c.column("AXISPOS");
        for (size_t n = 0; n < c.rows.size(); ++n) {
            const auto p = parseNumber(c.cell(n, cPos));
            const auto v = parseNumber(c.cell(n, col));
            if (!p || !std::isfinite(*p)) throw InputError(row.com, c.lines[n], "AXISPOS is not a number");
            if (!v || !std::isfinite(*v)) throw InputError(row.com, c.lines[n], fmt::format("C{} is not a number", row.column));
            if (!ct.nodes.empty() && !(*p / scale > ct.nodes.back()))
                throw InputError(row.com, c.lines[n], "AXISPOS must increase from row to row");
            ct.nodes.push_back(*p / scale);
            ct.values.push_back((tool ? -1.0 : 1.0) * *v * (row.component >= 3 ? kDeg : 1.0));
        }
        if (ct.nodes.size() < 2) throw InputError(row.com, 2, "a table needs at least two rows");
        if (l.modulo) {
            const int last = c.lines.back();
            if (std::abs((ct.nodes.back() - ct.nodes.front()) * scale - 360.0) > 1e-6)
                throw InputError(row.com, last, fmt::format("table of modulo axis {} must span one revolution (last AXISPOS = first + 360)", l.name));
            if (std::abs(ct.values.back() - ct.values.front()) > 1e-12)
                throw InputError(row.com, last, fmt::format("table of modulo axis {} does not close on itself (C{} of the last row differs from the first)",
                                                            l.name, row.column));
            ct.nodes.pop_back();
            ct.values.pop_back();
        }
        out.tables.push_back(std::move(ct));
    };
    // Tool side, walked from the tool: table rows right before their MachAxis.
    {
        std::vector<const WalkRow*> pending;
        for (const WalkRow& w : toolRows) {
            if (!w.com.empty()) {
                pending.push_back(&w);
                continue;
            }
            if (!pending.empty() && !w.axis)
                throw InputError(path, pending.front()->line, "on the tool side a COMPTAB row must come right before its MachAxis row");
            if (w.axis) {
                for (const WalkRow* p : pending) attach(*p, w.machineAxis, true);
                pending.clear();
            }
        }
        if (!pending.empty()) throw InputError(path, pending.front()->line, "on the tool side a COMPTAB row must come right before its MachAxis row");
        for (auto it = toolRows.rbegin(); it != toolRows.rend(); ++it) {
            if (!it->com.empty()) continue;
            if (it->axis) out.tool.push_back(ChainElement::motion(it->machineAxis, letterDirection(m.axisNames[it->machineAxis])));
            else out.tool.push_back(ChainElement::constant(transPose(it->component, -it->value)));
        }
    }
    // Table side, walked from the base: table rows right after their MachAxis.
    {
        int lastAxis = -1;
        for (const WalkRow& w : wpRows) {
            if (!w.com.empty()) {
                if (lastAxis < 0) throw InputError(path, w.line, "on the table side a COMPTAB row must come right after its MachAxis row");
                attach(w, lastAxis, false);
                continue;
            }
            if (w.axis) {
                lastAxis = w.machineAxis;
                out.workpiece.push_back(ChainElement::motion(w.machineAxis, letterDirection(m.axisNames[w.machineAxis])));
            } else {
                lastAxis = -1;
                out.workpiece.push_back(ChainElement::constant(transPose(w.component, w.value)));
            }
        }
    }
    return out;
}

}  // namespace cnccomp::controllers::heidenhain
