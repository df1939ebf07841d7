// ISG / Beckhoff TF5280 volumetric compensation backend: the ISO 230 error parameters of the machine (position
// errors X0C …, component errors EXX … as tables over their axis, tool zero position/orientation P0/N0) in an
// ISG_CSV file with its compensation list; and an apply model that rebuilds the controller's error model from
// the files and solves it for the nominal tool pose at every command (what a volumetric compensation does).
#include <algorithm>
#include <cmath>
#include <set>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "controllers/common/controller_model.hpp"
#include "controllers/common/files.hpp"
#include "controllers/common/header.hpp"
#include "controllers/common/tcp_solver.hpp"
#include "controllers/isg/isg_files.hpp"

namespace cnccomp::controllers::isg {
namespace {

constexpr const char* kLis = "volcomp.lis";
constexpr const char* kCsv = "volcomp.csv";
constexpr int kMaxRecords = 2000;  // [G] vol_comp[0].max_records of the example start-up list
const std::string kLetters = "XYZABC";
const char* kToolZero[6] = {"P0X", "P0Y", "P0Z", "N0X", "N0Y", "N0Z"};

/// "X0C" for "EX0C" when the name is an ISO 230 position error, else "".
std::string isoPosition(const std::string& n) {
    if (n.size() == 4 && n[0] == 'E' && kLetters.find(n[1]) != std::string::npos && n[2] == '0' &&
        kLetters.find(n[3]) != std::string::npos)
        return n.substr(1);
    return "";
}

/// True when the name is the ISO component error of its link's axis along its component ("EXX", "ECC", "EYX").
bool isoComponent(const MachineModel& m, const DeviationDef& d) {
    const Link& l = m.chain(d.side).links[d.link];
    return d.name.size() == 3 && d.name[0] == 'E' && d.name[1] == kLetters[d.component] && l.name.size() == 1 &&
           d.name[2] == l.name[0];
}

/// Index of the tool chain's last link when it is fixed (the spindle carrying the tool), else -1.
int toolZeroLink(const MachineModel& m) {
    const int n = static_cast<int>(m.tool.links.size());
    return n > 0 && m.tool.links[n - 1].kind == AxisKind::Fixed ? n - 1 : -1;
}

std::string chainOf(const MachineModel& m) {
    std::string s;
    for (auto it = m.tool.links.rbegin(); it != m.tool.links.rend(); ++it)
        if (it->kind != AxisKind::Fixed) s += it->name;
    for (const Link& l : m.workpiece.links)
        if (l.kind != AxisKind::Fixed) s += l.name;
    return s;
}

int workpieceAxisCount(const MachineModel& m) {
    int n = 0;
    for (const Link& l : m.workpiece.links) n += l.kind != AxisKind::Fixed;
    return n;
}

void checkAxes(const MachineModel& m) {
    for (const std::string& a : m.axisNames)
        if (a.size() != 1 || kLetters.find(a[0]) == std::string::npos)
            throw ModelError(fmt::format("machine '{}': ISG volumetric compensation knows the axes X Y Z A B C, not '{}'", m.name, a));
}

/// Tool zero pose (P0, N0) with the tool-zero link's error e: bMt(0) · E(e).
std::array<double, 6> toolZero(const MachineModel& m, const Vec6& e) {
    const Kinematics nominal(m);
    const Pose p = nominal.baseToTool(AxisVector::Zero(m.axisCount())) * errorTransform(e);
    const Vec3 n = p.linear() * m.toolDirection;
    return {p.translation().x(), p.translation().y(), p.translation().z(), n.x(), n.y(), n.z()};
}

/// Record positions (internal units) of a component table over an axis.
std::vector<double> recordNodes(const MachineModel& m, int axis, const std::vector<int>& defs) {
    const Link& l = m.axisLink(axis);
    bool allTables = true;
    std::set<double> nodes;
    for (int k : defs) {
        const ComponentBasis& b = m.deviations[k].basis;
        allTables &= b.type == ComponentBasis::Type::Table;
        nodes.insert(b.nodes.begin(), b.nodes.end());
    }
    std::set<double> s;
    if (l.modulo) {
        s = {0.0, 2 * kPi};
        if (allTables) {
            for (double n : nodes) {
                double u = std::fmod(n, 2 * kPi);
                if (u < 0) u += 2 * kPi;
                s.insert(u);
            }
        } else {
            for (int i = 0; i <= 180; ++i) s.insert(i * 2 * kDeg);
        }
    } else {
        if (!std::isfinite(l.min) || !std::isfinite(l.max) || !(l.max > l.min))
            throw ModelError(fmt::format("axis {} has no finite travel: an ISG table needs one", l.name));
        s = {l.min, l.max};
        if (allTables) {
            for (double n : nodes)
                if (n > l.min && n < l.max) s.insert(n);
        } else {
            for (int i = 0; i <= 180; ++i) s.insert(l.min + (l.max - l.min) * i / 180);
        }
    }
    std::vector<double> out;
    for (double u : s)
        if (out.empty() || u - out.back() > 1e-12) out.push_back(u);
    return out;
}

class IsgApplied final : public AppliedCompensation {
public:
    IsgApplied(const MachineModel& m, std::unique_ptr<MachineModel> controller, const std::map<std::string, double>& location,
               const Vec6& toolZeroError, const std::map<std::string, std::vector<double>>& tables)
        : model_(std::move(controller)), set_(*model_), nominal_(m) {
        for (size_t i = 0; i < model_->deviations.size(); ++i) {
            const DeviationDef& d = model_->deviations[i];
            if (d.kind == DeviationKind::Component) {
                const auto& v = tables.at(d.name);
                for (int k = 0; k < d.size(); ++k) set_.values[d.offset + k] = v[k];
            } else if (d.name.starts_with("ISG_P0")) {
                set_.values[d.offset] = toolZeroError[d.component];
            } else if (auto it = location.find(d.name); it != location.end()) {
                set_.values[d.offset] = it->second;
            }
        }
        actual_ = std::make_unique<Kinematics>(*model_, set_);
        axisWeight_ = m.axisCount() >= 5 ? 100.0 : 1e-3;  // fewer than five axes: the tip first
    }
    AxisVector driveCommands(const AxisVector& q) const override { return driveCommandsForTool(q, 0.0); }
    AxisVector driveCommandsForTool(const AxisVector& q, double toolLength) const override {
        const Vec3 tip = nominal_.toolPoint(toolLength);
        return compensatedCommands(*actual_, toolPose(nominal_, q, tip), tip, q, 6, axisWeight_);
    }

private:
    std::unique_ptr<MachineModel> model_;
    DeviationSet set_;
    Kinematics nominal_;
    std::unique_ptr<Kinematics> actual_;
    double axisWeight_ = 100.0;
};

class IsgBackend final : public Backend {
public:
    std::string_view name() const override { return "isg"; }
    std::string_view description() const override {
        return "ISG / Beckhoff TwinCAT CNC TF5280 volumetric compensation: ISG_CSV error table and compensation list";
    }

    EmitResult emit(const EmitRequest& r) const override {
        const MachineModel& m = r.machine;
        const DeviationSet& d = r.deviations;
        checkAxes(m);
        EmitResult out;
        std::vector<int> position;
        std::map<int, std::vector<int>> components;  // axis → deviation indices
        const int tz = toolZeroLink(m);
        Vec6 tzError = Vec6::Zero();
        for (size_t k = 0; k < m.deviations.size(); ++k) {
            if (!d.present[k]) continue;
            const DeviationDef& def = m.deviations[k];
            const Link& l = m.chain(def.side).links[def.link];
            if (def.kind == DeviationKind::Component) {
                if (isoComponent(m, def)) {
                    components[l.axisIndex].push_back(static_cast<int>(k));
                    out.compensated.push_back({def.name, fmt::format("component error {} as a table over {}", def.name, l.name)});
                } else {
                    out.notCompensated.push_back({def.name, "not an ISO 230 component-error name of its axis (E<component><axis>)"});
                }
                continue;
            }
            if (l.kind != AxisKind::Fixed) {
                const std::string iso = isoPosition(def.name);
                if (!iso.empty()) {
                    position.push_back(static_cast<int>(k));
                    out.compensated.push_back({def.name, fmt::format("position error {}", iso)});
                } else {
                    out.notCompensated.push_back({def.name, "not an ISO 230 position-error name (E<c>0<axis>)"});
                }
            } else if (def.side == Side::Tool && def.link == tz) {
                tzError[def.component] += d.values[def.offset];
                out.compensated.push_back({def.name, def.isAngle() ? "tool zero orientation N0X N0Y N0Z" : "tool zero position P0X P0Y P0Z"});
            } else {
                out.notCompensated.push_back({def.name, fmt::format("error of the fixed link {}: no ISG parameter takes it", l.name)});
            }
        }
        // Parameter file.
        std::string body;
        int records = 0;
        std::string head, row;
        if (tz >= 0) {
            const auto z = toolZero(m, tzError);
            for (int i = 0; i < 6; ++i) {
                head += fmt::format("{}{}", head.empty() ? "" : " ", kToolZero[i]);
                row += fmt::format("{}{}", row.empty() ? "" : " ", fixed(z[i], i < 3 ? 9 : 12));
            }
        }
        for (int k : position) {
            const DeviationDef& def = m.deviations[k];
            head += fmt::format("{}{}", head.empty() ? "" : " ", isoPosition(def.name));
            row += fmt::format("{}{}", row.empty() ? "" : " ", fixed(d.values[def.offset], def.isAngle() ? 12 : 9));
        }
        if (!head.empty()) {
            body += "// position errors (mm, rad) and tool zero position P0 (mm) / orientation N0\n" + head + "\n" + row + "\n";
            ++records;
        }
        std::vector<std::pair<int, std::vector<int>>> byLetter(components.begin(), components.end());
        std::sort(byLetter.begin(), byLetter.end(), [&](const auto& a, const auto& b) {
            return kLetters.find(m.axisNames[a.first]) < kLetters.find(m.axisNames[b.first]);
        });
        for (const auto& [axis, defs] : byLetter) {
            const Link& l = m.axisLink(axis);
            const bool rotary = l.kind == AxisKind::Rotary;
            if (!body.empty()) body += "#\n";
            body += fmt::format("// component errors over {} ({}; errors in mm and rad){}\n", l.name, rotary ? "deg" : "mm",
                                l.modulo ? ", one turn closing on itself" : "");
            body += l.name;
            for (int k : defs) body += " " + m.deviations[k].name;
            body += "\n";
            const auto nodes = recordNodes(m, axis, defs);
            std::vector<std::string> first;
            for (size_t i = 0; i < nodes.size(); ++i) {
                std::string line = fixed(nodes[i] / (rotary ? kDeg : 1.0), 6);
                for (size_t c = 0; c < defs.size(); ++c) {
                    const DeviationDef& def = m.deviations[defs[c]];
                    const double v = def.basis.evaluate(nodes[i], d.values.data() + def.offset, l.modulo);
                    if (!std::isfinite(v) || std::abs(v) > (def.isAngle() ? 0.1 : 10.0))
                        throw ModelError(fmt::format("{} = {} at {} {:.4f} is outside the plausible range (check the units)", def.name,
                                                     v, l.name, nodes[i] / (rotary ? kDeg : 1.0)));
                    std::string text = fixed(v, def.isAngle() ? 12 : 9);
                    if (l.modulo && i + 1 == nodes.size()) text = first[c];  // closes on itself
                    if (i == 0) first.push_back(text);
                    line += " " + text;
                }
                body += line + "\n";
                ++records;
            }
        }
        if (records > kMaxRecords)
            throw ModelError(fmt::format("the ISG table has {} records, more than max_records {}", records, kMaxRecords));
        std::vector<std::string> notes{
            "values in mm and rad, arguments in mm and degrees (TF5280 ISG CSV format)",
            "[G] position errors are placed as in the machine description (cnccomp's ISO 230-1 reading); confirm against the ISG kinematic model",
            "[G] P0 = spindle reference point, N0 = tool direction at zero axis positions; the active tool length is applied along N0",
            "[G] records are interpolated linearly, end values held; a modulo axis table spans 0..360 deg and closes on itself",
            fmt::format("[G] start-up list: vol_comp[0].max_records >= {}", records)};
        const HeaderInfo h = makeHeaderInfo(r, "ISG / Beckhoff TwinCAT CNC TF5280 volumetric compensation (ISG_CSV)", out, notes);
        IsgConfig cfg;
        int n = 1;
        for (char c : kLetters)
            if (m.axisIndex(std::string(1, c)) >= 0) cfg.axisNumber[c] = n++;
        cfg.chain = chainOf(m);
        cfg.workpieceAxes = workpieceAxisCount(m);
        cfg.files.emplace_back(kCsv, "ISG_CSV");
        out.files.push_back({kLis, formatIsgConfig(cfg, formatHeader(h, "# "))});
        out.files.push_back({kCsv, formatHeader(h, "// ") + body});
        return out;
    }

    std::unique_ptr<AppliedCompensation> apply(const MachineModel& m, const std::vector<OutputFile>& files) const override {
        checkAxes(m);
        const IsgConfig cfg = parseIsgConfig(requireFile(files, kLis, "ISG").content, kLis);
        if (cfg.chain != chainOf(m) || cfg.workpieceAxes != workpieceAxisCount(m))
            throw InputError(kLis, 0, fmt::format("chain {} with {} workpiece axes does not describe machine '{}' ({}, {})", cfg.chain,
                                                  cfg.workpieceAxes, m.name, chainOf(m), workpieceAxisCount(m)));
        if (static_cast<int>(cfg.axisNumber.size()) != m.axisCount())
            throw InputError(kLis, 0, fmt::format("{} axes assigned, machine '{}' has {}", cfg.axisNumber.size(), m.name, m.axisCount()));
        for (const auto& [letter, num] : cfg.axisNumber)
            if (m.axisIndex(std::string(1, letter)) < 0) throw InputError(kLis, 0, fmt::format("machine '{}' has no axis {}", m.name, letter));
        // The controller's model: the machine's chains and location errors, the tool zero as six errors of the
        // spindle link, component errors as the file's tables.
        auto model = std::make_unique<MachineModel>(m);
        const int tz = toolZeroLink(m);
        std::erase_if(model->deviations, [&](const DeviationDef& d) {
            return d.kind == DeviationKind::Component || (d.side == Side::Tool && d.link == tz);
        });
        std::map<std::string, double> location;
        std::map<std::string, std::vector<double>> tables;
        Vec6 tzError = Vec6::Zero();
        for (const auto& [file, format] : cfg.files) {
            const std::string& text = requireFile(files, file, "ISG").content;
            for (const IsgBlock& b : parseIsgCsv(text, file)) {
                const std::string& arg = b.columns[0];
                if (arg.size() == 1 && kLetters.find(arg[0]) != std::string::npos) {
                    const int axis = m.axisIndex(arg);
                    if (axis < 0) throw InputError(file, b.headerLine, fmt::format("machine '{}' has no axis {}", m.name, arg));
                    const Link& l = m.axisLink(axis);
                    const double scale = l.kind == AxisKind::Rotary ? kDeg : 1.0;
                    std::vector<double> nodes;
                    for (const auto& row : b.rows) nodes.push_back(row[0] * scale);
                    for (size_t i = 1; i < nodes.size(); ++i)
                        if (!(nodes[i] > nodes[i - 1])) throw InputError(file, b.rowLines[i], fmt::format("{} must increase", arg));
                    size_t used = nodes.size();
                    if (l.modulo) {
                        if (nodes.front() != 0.0 || std::abs(nodes.back() - 2 * kPi) > 1e-9)
                            throw InputError(file, b.headerLine, fmt::format("the table of modulo axis {} must span 0..360", arg));
                        for (size_t c = 1; c < b.columns.size(); ++c)
                            if (b.rows.front()[c] != b.rows.back()[c])
                                throw InputError(file, b.rowLines.back(), fmt::format("{} does not close on itself over one turn", b.columns[c]));
                        used = nodes.size() - 1;
                    }
                    for (size_t c = 1; c < b.columns.size(); ++c) {
                        const std::string& col = b.columns[c];
                        const size_t comp = col.size() == 3 ? kLetters.find(col[1]) : std::string::npos;
                        if (col.size() != 3 || col[0] != 'E' || comp == std::string::npos || col[2] != arg[0])
                            throw InputError(file, b.headerLine, fmt::format("'{}' is not a component error of {}", col, arg));
                        DeviationDef d;
                        d.name = col;
                        d.side = m.axisSide(axis);
                        const Chain& ch = m.chain(d.side);
                        for (int i = 0; i < static_cast<int>(ch.links.size()); ++i)
                            if (ch.links[i].axisIndex == axis) d.link = i;
                        d.component = static_cast<int>(comp);
                        d.kind = DeviationKind::Component;
                        d.basis.type = ComponentBasis::Type::Table;
                        d.basis.nodes.assign(nodes.begin(), nodes.begin() + static_cast<long>(used));
                        std::vector<double> v;
                        for (size_t i = 0; i < used; ++i) v.push_back(b.rows[i][c]);
                        tables[col] = v;
                        model->deviations.push_back(d);
                    }
                    continue;
                }
                if (b.rows.size() != 1) throw InputError(file, b.rowLines[1], "position errors take one data row");
                for (size_t c = 0; c < b.columns.size(); ++c) {
                    const std::string& col = b.columns[c];
                    const auto* tzName = std::find(std::begin(kToolZero), std::end(kToolZero), col);
                    if (tzName != std::end(kToolZero)) {
                        if (tz < 0) throw InputError(file, b.headerLine, "P0/N0 given but the tool chain ends with no fixed spindle link");
                        tzError[tzName - std::begin(kToolZero)] = b.rows[0][c];  // absolute pose for now
                        continue;
                    }
                    const int k = m.deviationIndex("E" + col);
                    if (col.size() != 3 || col[1] != '0' || k < 0 || m.deviations[k].kind != DeviationKind::Location)
                        throw InputError(file, b.headerLine, fmt::format("'{}' is not a position error of machine '{}'", col, m.name));
                    location["E" + col] = b.rows[0][c];
                }
            }
        }
        Vec6 tzLocal = Vec6::Zero();
        if (tz >= 0) {
            // P0/N0 back to the spindle link's error: translation in its frame, and the smallest rotation taking the
            // tool direction to N0 (a roll about the tool axis moves no tool point on the axis).
            const Kinematics nominal(m);
            const Pose z = nominal.baseToTool(AxisVector::Zero(m.axisCount()));
            const Vec3 p0(tzError[0], tzError[1], tzError[2]), n0 = Vec3(tzError[3], tzError[4], tzError[5]);
            if (n0.norm() < 1e-9) throw InputError(kCsv, 0, "N0 must be a non-zero vector");
            const Vec3 t = z.linear().transpose() * (p0 - z.translation());
            const Vec3 n = z.linear().transpose() * n0.normalized();
            const Vec3 axis = m.toolDirection.cross(n);
            const double angle = std::atan2(axis.norm(), m.toolDirection.dot(n));
            tzLocal.head<3>() = t;
            if (axis.norm() > 0) tzLocal.tail<3>() = axis.normalized() * angle;
            for (int c = 0; c < 6; ++c) {
                DeviationDef d;
                d.name = fmt::format("ISG_P0_{}", c);
                d.side = Side::Tool;
                d.link = tz;
                d.component = c;
                model->deviations.push_back(d);
            }
        }
        try {
            model->finalize();
        } catch (const ModelError& e) {
            throw InputError(kCsv, 0, e.what());
        }
        return std::make_unique<IsgApplied>(m, std::move(model), location, tzLocal, tables);
    }
};

const RegisterBackend reg(std::make_unique<IsgBackend>());

}  // namespace
}  // namespace cnccomp::controllers::isg
