// ISG / Beckhoff TF5280 volumetric compensation backend. The emitter re-expresses the machine description in the
// ISG model (isg_model.hpp): the chain from the workpiece over the machine origin to the tool tip, every axis at its
// machine zero with its centre of rotation, the tool zero P0/N0, and per axis the error transforms that model puts on
// it: position errors X0L..C0L and component tables EXL..ECL over L. The apply model (isg_model.cpp) reads the files
// back with the documents' conventions only; it never uses the description's chains.
#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "controllers/common/axis_table.hpp"
#include "controllers/common/controller_model.hpp"
#include "controllers/common/directional.hpp"
#include "controllers/common/files.hpp"
#include "cnccomp/io/text_util.hpp"
#include "controllers/common/header.hpp"
#include "controllers/common/set_backlash.hpp"
#include "controllers/isg/isg_files.hpp"
#include "controllers/isg/laser_lsec.hpp"
#include "controllers/isg/isg_model.hpp"

namespace cnccomp::controllers::isg {
using namespace cnccomp::controllers::common;
using namespace cnccomp::io;
namespace {

constexpr const char* kLis = "volcomp.lis";
constexpr const char* kCsv = "volcomp.csv";
constexpr int kMaxRecords = 2000;  // [G] vol_comp[0].max_records of the example start-up list
const std::string kLetters = "XYZABC";

void checkAxes(const MachineModel& m) {
    int linear = 0;
    for (const std::string& a : m.axisNames) {
        if (a.size() != 1 || kLetters.find(a[0]) == std::string::npos)
            throw ModelError(fmt::format("machine '{}': ISG volumetric compensation knows the axes X Y Z A B C, not '{}'", m.name, a));
        linear += kLetters.find(a[0]) < 3;
    }
    if (linear != 3)
        throw ModelError(fmt::format("machine '{}': ISG volumetric compensation needs precisely the linear axes X, Y and Z "
                                     "(TF5280 \"Overview\")", m.name));
}

Pose shifted(const Vec3& t) {
    Pose p = Pose::Identity();
    p.translation() = t;
    return p;
}

/// Translation and rotation vector of a pose (the inverse of errorTransform).
Vec6 sixOf(const Pose& p) {
    Vec6 v;
    v.head<3>() = p.translation();
    const Eigen::AngleAxisd aa(p.linear());
    v.tail<3>() = aa.axis() * aa.angle();
    return v;
}

/// One axis in the ISG model, as the emitter derives it from the description.
struct IsgAxis {
    int machineAxis = -1;
    Side side = Side::Tool;
    int link = -1;
    char letter = 'X';
    bool rotary = false;
    Vec3 centre = Vec3::Zero();                  ///< centre of rotation at the controller's zero (rotary axes)
    Pose before = Pose::Identity();              ///< link frame before its motion, at the controller's zero
    Pose after = Pose::Identity();               ///< the same after its own machine-zero motion
    Pose position = Pose::Identity();            ///< ISG position error transform (pivot: centre / origin)
    Pose trailing = Pose::Identity();            ///< constant errors after the axis (fixed links behind it), ISG pivot
    std::vector<int> components;                 ///< component deviations of the link
    std::vector<std::string> sources, trailingSources;
};

/// The ISG pivot of an error transform given in the machine frame (about the origin): about the centre of a rotary
/// axis, about the origin of a linear one.
Pose toPivot(const IsgAxis& a, const Pose& machineFrame) {
    return a.rotary ? shifted(-a.centre) * machineFrame * shifted(a.centre) : machineFrame;
}

struct IsgPlan {
    std::vector<IsgAxis> workpiece, tool;        ///< each from the bed outwards
    Pose toolZero = Pose::Identity();            ///< tool chain end at the controller's zero (nominal)
    EmitResult coverage;
};

IsgPlan plan(const MachineModel& m, const DeviationSet& d) {
    IsgPlan out;
    for (Side side : {Side::Workpiece, Side::Tool}) {
        const Chain& c = m.chain(side);
        auto& axes = side == Side::Tool ? out.tool : out.workpiece;
        Pose frame = Pose::Identity();       // nominal, all axes at their machine zero
        Pose pending = Pose::Identity();     // errors of fixed links since the last axis (machine frame)
        std::vector<std::string> pendingNames;
        for (int i = 0; i < static_cast<int>(c.links.size()); ++i) {
            const Link& l = c.links[i];
            const Pose before = frame * l.placement;
            const Pose error = before * errorTransform(linkLocationError(m, d.values, side, i)) * before.inverse(Eigen::Isometry);
            std::vector<std::string> names;
            for (size_t k = 0; k < m.deviations.size(); ++k) {
                const DeviationDef& def = m.deviations[k];
                if (d.present[k] && def.side == side && def.link == i && def.kind == DeviationKind::Location) names.push_back(def.name);
            }
            if (l.kind == AxisKind::Fixed) {
                pending = pending * error;
                pendingNames.insert(pendingNames.end(), names.begin(), names.end());
                frame = before;
                continue;
            }
            IsgAxis a;
            a.machineAxis = l.axisIndex;
            a.side = side;
            a.link = i;
            a.letter = l.name[0];
            a.rotary = l.kind == AxisKind::Rotary;
            const Vec3 dir = before.linear() * l.direction;
            const Vec3 want = Vec3::Unit(static_cast<int>(kLetters.find(a.letter) % 3));
            if ((dir - want).norm() > 1e-9)
                throw ModelError(fmt::format("isg: axis {} {} along ({:g} {:g} {:g}) at its machine zero; the ISG model {} it "
                                             "along +{}",
                                             l.name, a.rotary ? "turns" : "moves", dir.x(), dir.y(), dir.z(),
                                             a.rotary ? "turns" : "moves", "xyz"[kLetters.find(a.letter) % 3]));
            a.before = before;
            Pose motion = Pose::Identity();
            if (a.rotary) motion.linear() = axisRotation(l.direction, l.machineZero);
            else motion.translation() = l.direction * l.machineZero;
            a.after = before * motion;
            a.centre = before.translation();
            a.position = toPivot(a, pending * error);
            a.sources = pendingNames;
            a.sources.insert(a.sources.end(), names.begin(), names.end());
            for (size_t k = 0; k < m.deviations.size(); ++k) {
                const DeviationDef& def = m.deviations[k];
                if (d.present[k] && def.side == side && def.link == i && def.kind == DeviationKind::Component)
                    a.components.push_back(static_cast<int>(k));
            }
            for (const std::string& n : pendingNames)
                out.coverage.compensated.push_back({n, fmt::format("folded into the position errors of {} (ISG model)", l.name)});
            for (const std::string& n : names)
                out.coverage.compensated.push_back({n, fmt::format("position errors of {} (X0{}..C0{})", l.name, l.name, l.name)});
            pending = Pose::Identity();
            pendingNames.clear();
            axes.push_back(a);
            frame = a.after;
        }
        if (side == Side::Tool) out.toolZero = frame;
        if (pendingNames.empty()) continue;
        if (axes.empty()) {
            for (const std::string& n : pendingNames)
                out.coverage.notCompensated.push_back(
                    {n, "error of the fixed workpiece side, which no axis carries: no ISG parameter takes it (probe the "
                        "workpiece zero instead)"});
            continue;
        }
        // Errors behind the last axis (the spindle, a table plate) move with it: constant component errors of that axis.
        IsgAxis& last = axes.back();
        last.trailing = toPivot(last, pending);
        last.trailingSources = pendingNames;
        for (const std::string& n : pendingNames)
            out.coverage.compensated.push_back({n, fmt::format("constant component errors of {} (E?{})", last.letter, last.letter)});
    }
    for (size_t k = 0; k < m.deviations.size(); ++k) {
        const DeviationDef& def = m.deviations[k];
        if (!d.present[k] || def.kind != DeviationKind::Component) continue;
        const Link& l = m.chain(def.side).links[def.link];
        out.coverage.compensated.push_back({def.name, fmt::format("component errors of {}: table over {} (E?{})", l.name, l.name, l.name)});
    }
    return out;
}

/// Record positions of a table over an axis in the controller's coordinates (internal units): the component
/// deviations' own nodes when all are tables, else 181 points; a modulo axis spans one turn (0 .. 2π).
std::vector<double> recordNodes(const MachineModel& m, const IsgAxis& a) {
    const Link& l = m.axisLink(a.machineAxis);
    bool allTables = !a.components.empty();
    std::set<double> nodes;
    for (int k : a.components) {
        const ComponentBasis& b = m.deviations[k].basis;
        allTables &= b.type == ComponentBasis::Type::Table;
        for (double n : b.nodes) nodes.insert(n - l.machineZero);
    }
    const int count = a.components.empty() ? 1 : 180;
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
            for (int i = 0; i <= count; ++i) s.insert(i * 2 * kPi / count);
        }
    } else {
        const double lo = l.min - l.machineZero, hi = l.max - l.machineZero;
        if (!std::isfinite(lo) || !std::isfinite(hi) || !(hi > lo))
            throw ModelError(fmt::format("axis {} has no finite travel: an ISG table needs one", l.name));
        s = {lo, hi};
        if (allTables) {
            for (double n : nodes)
                if (n > lo && n < hi) s.insert(n);
        } else {
            for (int i = 0; i <= count; ++i) s.insert(lo + (hi - lo) * i / count);
        }
    }
    std::vector<double> out;
    for (double u : s)
        if (out.empty() || u - out.back() > 1e-12) out.push_back(u);
    return out;
}

std::string chainOf(const IsgPlan& p) {
    // TF5240: "in the sequence along the path from the workpiece to the machine origin and from there to the tool tip".
    std::string s;
    for (auto it = p.workpiece.rbegin(); it != p.workpiece.rend(); ++it) s += it->letter;
    for (const IsgAxis& a : p.tool) s += a.letter;
    return s;
}

void addColumn(std::string& head, std::string& row, const std::string& name, double v, int decimals) {
    head += fmt::format("{}{}", head.empty() ? "" : " ", name);
    row += fmt::format("{}{}", row.empty() ? "" : " ", fixed(v, decimals));
}

std::string backlashFileName(const std::string& axis) { return "backlash_" + axis + ".lis"; }

/// An axis' backlash list (isgAxisBacklash): kopf.log_achs_name, lr_param.anwahl_losekomp (0 or 1), getriebe[0].lose
/// (0.1 um) into `beta` (mm, per machine axis). InputError file:line for anything else.
void readBacklash(const MachineModel& m, const OutputFile& f, std::vector<double>& beta) {
    if (beta.empty()) beta.assign(static_cast<size_t>(m.axisCount()), 0.0);
    int axis = -1, selection = -1;
    double lose = 0;
    for (const TextLine& l : splitLines(f.content)) {
        const auto tok = tokens(l.text);
        if (tok.empty() || tok[0].front() == '#') continue;
        if (tok.size() != 2) throw InputError(f.name, l.number, "expected '<parameter> <value>'");
        if (tok[0] == "kopf.achs_nr") continue;
        if (tok[0] == "kopf.log_achs_name") {
            axis = m.axisIndex(std::string(tok[1]));
            if (axis < 0) throw InputError(f.name, l.number, fmt::format("machine '{}' has no axis {}", m.name, tok[1]));
            continue;
        }
        const auto v = parseNumber(tok[1]);
        if (!v) throw InputError(f.name, l.number, "expected a number");
        if (tok[0] == "lr_param.anwahl_losekomp" && (*v == 0 || *v == 1)) selection = static_cast<int>(*v);
        else if (tok[0] == "getriebe[0].lose") lose = *v * 1e-4;  // 0.1 um → mm
        else throw InputError(f.name, l.number, "expected kopf.*, lr_param.anwahl_losekomp 0|1 or getriebe[0].lose");
    }
    if (axis < 0 || selection < 0) throw InputError(f.name, 0, "needs kopf.log_achs_name and lr_param.anwahl_losekomp");
    beta[static_cast<size_t>(axis)] = selection == 1 ? lose : 0.0;
}

class IsgApplied final : public AppliedCompensation, public DirectionalCompensation {
public:
    IsgApplied(const MachineModel& m, IsgModel model, const IsgConfig& cfg) : machine_(&m), model_(std::move(model)) {
        for (char c : std::string("XYZ")) {
            linear_.push_back(m.requireAxis(std::string(1, c)));
            scale_.push_back(cfg.setToZero.find(c) != std::string::npos ? 0.0 : cfg.negate.find(c) != std::string::npos ? -1.0 : 1.0);
        }
    }
    AxisVector driveCommands(const AxisVector& q) const override { return driveCommandsForTool(q, 0.0); }
    AxisVector driveCommandsForTool(const AxisVector& q, double toolLength) const override {
        const MachineModel& m = *machine_;
        AxisVector p = m.toController(q);
        const auto values = [&](const AxisVector& x) {
            std::map<char, double> v;
            for (int a = 0; a < m.axisCount(); ++a) v[m.axisNames[a][0]] = m.axisLink(a).kind == AxisKind::Rotary ? x[a] / kDeg : x[a];
            return v;
        };
        const Vec3 target = model_.toolPoint(values(p), toolLength, false);
        // Tool position only (TF5280 "Overview"): X, Y and Z move until the erroneous model's tool point is the nominal one.
        for (int it = 0; it < 8; ++it) {
            const Vec3 r = target - model_.toolPoint(values(p), toolLength, true);
            if (r.norm() < 1e-12) break;
            Mat3 J;
            for (int k = 0; k < 3; ++k) {
                AxisVector h = p;
                h[linear_[k]] += 1e-3;
                J.col(k) = (model_.toolPoint(values(h), toolLength, true) - model_.toolPoint(values(p), toolLength, true)) / 1e-3;
            }
            const Vec3 step = J.partialPivLu().solve(r);
            for (int k = 0; k < 3; ++k) p[linear_[k]] += step[k];
        }
        // P-VOLC-00009 `negate` / `set_to_zero` of the compensation list: the compensation value of that Cartesian axis
        // (corrected minus programmed) negated or zeroed before it reaches the axis.
        const AxisVector programmed = m.toController(q);
        for (int k = 0; k < 3; ++k) p[linear_[k]] = programmed[linear_[k]] + scale_[k] * (p[linear_[k]] - programmed[linear_[k]]);
        return m.fromController(p);
    }
    const IsgModel& model() const { return model_; }
    /// The same plus each axis' backlash by the direction of motion (controllers/common/set_backlash.hpp).
    AxisVector driveCommandsMoving(const AxisVector& q, double toolLength, const AxisVector& motion) const override {
        return withBacklashOffsets(driveCommandsForTool(q, toolLength), backlash, motion);
    }
    /// getriebe[0].lose of each axis (mm; lr_param.anwahl_losekomp 1), empty without backlash files.
    std::vector<double> backlash;

private:
    const MachineModel* machine_;
    IsgModel model_;
    std::vector<int> linear_;
    std::vector<double> scale_;  ///< per X Y Z: 1, −1 (negate) or 0 (set_to_zero)
};

class IsgBackend final : public Backend {
public:
    std::string_view name() const override { return "isg"; }
    std::string_view description() const override {
        return "ISG / Beckhoff TwinCAT CNC TF5280 volumetric compensation: ISG_CSV error table and compensation list "
               "(tool position; tool orientation is not corrected)";
    }
    std::vector<std::string> checks() const override {
        return {"where the position errors act: cnccomp writes each axis' error transform at its machine zero, pivoting "
                "about its centre of rotation PXA.. (rotary) or the machine origin (linear); rotations as rotation "
                "vectors (A, B, C) in rad",
                "workpiece axes carry the errors of the table's own motion (cnccomp's reading; ISG inverts their motion)",
                "errors behind the last axis (spindle, table plate) are written as constant component errors of that axis",
                "the logical axis numbers (X 1, Y 2, ...) are written in the order X Y Z A B C: set them to the channel's",
                "vol_comp[0].max_records in the start-up list must be at least the record count in the file header",
                "P0, N0 and PXA.. are the machine-frame positions at all axes 0 (controller zero); compare with the "
                "channel's kinematic configuration before loading"};
    }

    EmitResult emit(const EmitRequest& r) const override {
        const MachineModel& m = r.machine;
        const DeviationSet& d = r.deviations;
        checkAxes(m);
        if (!d.values.allFinite()) throw ModelError("the deviation set holds a value that is not a finite number");
        const IsgPlan p = plan(m, d);
        EmitResult out = p.coverage;
        // One record: tool zero, centres of rotation, position errors.
        std::string head, row, body;
        const Vec3 p0 = p.toolZero.translation(), n0 = p.toolZero.linear() * m.toolDirection;
        for (int k = 0; k < 3; ++k) addColumn(head, row, fmt::format("P0{}", "XYZ"[k]), p0[k], 9);
        for (int k = 0; k < 3; ++k) addColumn(head, row, fmt::format("N0{}", "XYZ"[k]), n0[k], 12);
        std::vector<const IsgAxis*> all;
        for (const auto* side : {&p.workpiece, &p.tool})
            for (const IsgAxis& a : *side) all.push_back(&a);
        std::sort(all.begin(), all.end(), [](const IsgAxis* a, const IsgAxis* b) { return kLetters.find(a->letter) < kLetters.find(b->letter); });
        for (const IsgAxis* a : all)
            if (a->rotary)
                for (int k = 0; k < 3; ++k) addColumn(head, row, fmt::format("P{}{}", "XYZ"[k], a->letter), a->centre[k], 9);
        for (const IsgAxis* a : all) {
            const Vec6 e = sixOf(a->position);
            for (int k = 0; k < 6; ++k)
                if (e[k] != 0.0) addColumn(head, row, fmt::format("{}0{}", kLetters[k], a->letter), e[k], k < 3 ? 9 : 12);
        }
        body += "// tool zero P0 (mm) and orientation N0, centres of rotation P (mm), position errors (mm, rad)\n" + head + "\n" + row + "\n";
        int records = 1;
        for (const IsgAxis* a : all) {
            const bool constant = !a->trailingSources.empty();
            if (a->components.empty() && !constant) continue;
            const Link& l = m.axisLink(a->machineAxis);
            const auto nodes = recordNodes(m, *a);
            std::vector<Vec6> values;
            for (double u : nodes) {
                Vec6 c = Vec6::Zero();
                for (int k : a->components) {
                    const DeviationDef& def = m.deviations[k];
                    c[def.component] += def.basis.evaluate(u + l.machineZero, d.values.data() + def.offset, l.modulo);
                }
                // The link's component transform, seen in the machine frame at the axis' zero, then the ISG pivot.
                const Pose inMachine = a->after * errorTransform(c) * a->after.inverse(Eigen::Isometry);
                values.push_back(sixOf(toPivot(*a, inMachine) * a->trailing));
            }
            if (l.modulo) values.back() = values.front();  // closes on itself
            std::vector<int> cols;
            for (int k = 0; k < 6; ++k)
                for (const Vec6& v : values)
                    if (v[k] != 0.0) {
                        cols.push_back(k);
                        break;
                    }
            if (cols.empty()) continue;
            const bool rotary = l.kind == AxisKind::Rotary;
            body += fmt::format("#\n// component errors over {} ({}, machine coordinates; errors in mm and rad){}\n", l.name,
                                rotary ? "deg" : "mm", l.modulo ? ", one turn closing on itself" : "");
            body += l.name;
            for (int k : cols) body += fmt::format(" E{}{}", kLetters[k], a->letter);
            body += "\n";
            for (size_t i = 0; i < nodes.size(); ++i) {
                std::string line = fixed(nodes[i] / (rotary ? kDeg : 1.0), 6);
                for (int k : cols) {
                    const double v = values[i][k];
                    if (!std::isfinite(v) || std::abs(v) > (k >= 3 ? 0.1 : 10.0))
                        throw ModelError(fmt::format("E{}{} = {} at {} {:.4f} is outside the plausible range (check the units)",
                                                     kLetters[k], a->letter, v, l.name, nodes[i] / (rotary ? kDeg : 1.0)));
                    line += fmt::format(" {}", fixed(v, k >= 3 ? 12 : 9));
                }
                body += line + "\n";
                ++records;
            }
        }
        if (records > kMaxRecords)
            throw ModelError(fmt::format("the ISG table has {} records, more than max_records {}", records, kMaxRecords));
        const std::string chain = chainOf(p);
        std::vector<std::string> notes{
            fmt::format("chain {}: from the workpiece over the machine origin to the tool tip, {} workpiece axes (TF5240 "
                        "\"Example of an AC machine with cardanic table\", P-VOLC-00007)",
                        chain, p.workpiece.size()),
            frameNote(m),
            "absolute values: P0, N0 and the centres PXA.. are machine-frame positions at all axes 0 (controller zero); "
            "errors and tables replace any loaded before (not deltas)",
            "values in mm and rad, arguments in mm and degrees, in machine coordinates (TF5280 \"Units of measure\")",
            "signs: the errors are written as ISO 230-1 / TF5280 define them (the error of the axis, not its correction); the "
            "compensation values the control computes from them are used as computed: this list sets neither 'negate' nor "
            "'set_to_zero' (P-VOLC-00009 \"Negate compensation values\", TF5280 \"Modification of compensation values "
            "(optional)\"); an entry 'negate XYZ' in this list would flip every correction and double the error",
            "tool position only: the volumetric compensation does not correct tool orientation (TF5280 \"Overview\")",
            "[G] each axis' errors act at its machine zero, about its centre of rotation (rotary) or the origin (linear); "
            "workpiece axes carry the table's own errors",
            "[G] records are interpolated linearly, end values held; a table over 0..360 deg closes on itself",
            fmt::format("[G] start-up list: vol_comp[0].max_records >= {}", records)};
        IsgConfig cfg;
        int n = 1;
        for (char c : kLetters)
            if (m.axisIndex(std::string(1, c)) >= 0) cfg.axisNumber[c] = n++;
        // Reversal values → each axis' backlash parameters (laser_lsec.hpp's lines; set_backlash.hpp).
        std::vector<OutputFile> backlashFiles;
        for (const AxisBacklash& b : backlashOfSet(r)) {
            const int number = cfg.axisNumber.at(b.name[0]);
            backlashFiles.push_back({backlashFileName(b.name), isgAxisBacklash(number, b.name, b.backlashUm)});
            out.compensated.push_back({"B" + b.name, fmt::format("axis {} (kopf.achs_nr {}): getriebe[0].lose = {} x 0.1 um (= -B{}), "
                                                                 "lr_param.anwahl_losekomp = 1, in {}",
                                                                 b.name, number, std::lround(b.backlashUm * 10), b.name,
                                                                 backlashFileName(b.name))});
        }
        const HeaderInfo h = makeHeaderInfo(r, "ISG / Beckhoff TwinCAT CNC TF5280 volumetric compensation (ISG_CSV)", out, notes);
        cfg.chain = chain;
        cfg.workpieceAxes = static_cast<int>(p.workpiece.size());
        cfg.files.emplace_back(kCsv, "ISG_CSV");
        out.files.push_back({kLis, formatIsgConfig(cfg, formatHeader(h, "# "))});
        out.files.push_back({kCsv, formatHeader(h, "// ") + body});
        for (OutputFile& f : backlashFiles) {
            f.content = formatHeader(h, "# ") +
                        "# backlash of this axis for its axis parameter list (TF5200 axis compensation: P-AXIS-00021 "
                        "selection 1 = reference approach in +, P-AXIS-00103 size in 0.1 um, > 0 between drive and slide)\n" +
                        f.content;
            out.files.push_back(std::move(f));
        }
        return out;
    }

    std::unique_ptr<AppliedCompensation> apply(const MachineModel& m, const std::vector<OutputFile>& files) const override {
        checkAxes(m);
        const IsgConfig cfg = parseIsgConfig(requireFile(files, kLis, "ISG").content, kLis);
        for (char c : cfg.chain)
            if (m.axisIndex(std::string(1, c)) < 0)
                throw InputError(kLis, 0, fmt::format("chain {} names axis {}, which machine '{}' lacks", cfg.chain, c, m.name));
        for (const std::string& a : m.axisNames)
            if (cfg.chain.find(a[0]) == std::string::npos)
                throw InputError(kLis, 0, fmt::format("chain {} lacks axis {} of machine '{}'", cfg.chain, a, m.name));
        std::vector<std::pair<std::string, std::vector<IsgBlock>>> blocks;
        for (const auto& [file, format] : cfg.files) blocks.emplace_back(file, parseIsgCsv(requireFile(files, file, "ISG").content, file));
        auto applied = std::make_unique<IsgApplied>(m, IsgModel(cfg, blocks), cfg);
        for (const OutputFile& f : files)
            if (f.name.starts_with("backlash_") && f.name.ends_with(".lis")) readBacklash(m, f, applied->backlash);
        return applied;
    }
};

const RegisterBackend reg(std::make_unique<IsgBackend>());

}  // namespace
}  // namespace cnccomp::controllers::isg
