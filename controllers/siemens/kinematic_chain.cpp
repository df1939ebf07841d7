#include "controllers/siemens/kinematic_chain.hpp"

#include <cmath>
#include <map>
#include <optional>
#include <set>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "controllers/siemens/siemens_syntax.hpp"

namespace cnccomp::controllers::siemens {
using namespace cnccomp::controllers::common;
namespace {

struct Element {
    std::string name, type, axis, doc;
    Vec3 dir = Vec3::Zero();
    double aOffDeg = 0;
};

void linkElements(const MachineModel& m, const Link& l, const Pose& pose, const std::string& prefix,
                  std::vector<Element>& out) {
    const Vec3 t = pose.translation();
    const bool fixed = l.kind == AxisKind::Fixed;
    if (fixed || t.norm() > 1e-12) out.push_back({prefix + l.name + (fixed ? "" : "_OFF"), "OFFSET", "", "", t, 0.0});
    Mat3 swing = pose.linear();
    double twist = 0;
    if (l.kind == AxisKind::Rotary) {
        // Swing-twist split: the twist about the axis' own direction is its zero offset ($NK_A_OFF).
        Eigen::Quaterniond q(pose.linear());
        if (q.w() < 0) q.coeffs() = -q.coeffs();
        twist = 2 * std::atan2(q.vec().dot(l.direction), q.w());
        swing = pose.linear() * axisRotation(l.direction, -twist);
    }
    const Eigen::AngleAxisd aa(swing);
    if (std::abs(aa.angle()) > 1e-15)
        out.push_back({prefix + l.name + "_ROT", "ROT_CONST", "", "", aa.axis(), aa.angle() / kDeg});
    if (!fixed)
        out.push_back({prefix + l.name, l.kind == AxisKind::Linear ? "AXIS_LIN" : "AXIS_ROT",
                       axisName(m, l.axisIndex), "", l.direction, twist / kDeg});
}

}  // namespace

std::string formatKinematicChain(const MachineModel& m, const Plan& plan, const Options& o, const std::string& header) {
    std::vector<Element> branch[2];  // 0 tool, 1 part
    for (Side side : {Side::Tool, Side::Workpiece}) {
        auto& out = branch[side == Side::Tool ? 0 : 1];
        const std::string prefix = side == Side::Tool ? "T_" : "P_";
        const Chain& c = m.chain(side);
        const int s = sideIndex(side);
        for (size_t i = 0; i < c.links.size(); ++i) {
            // The NCK counts the axis from its machine zero: the chain holds the description's motion up to there.
            const Link& l = c.links[i];
            Pose zero = Pose::Identity();
            if (l.kind == AxisKind::Linear) zero.translation() = l.direction * l.machineZero;
            if (l.kind == AxisKind::Rotary) zero.linear() = axisRotation(l.direction, l.machineZero);
            linkElements(m, l, plan.placed[s][i] * zero, prefix, out);
        }
        const Pose& end = plan.end[s];
        if ((end.matrix() - Eigen::Matrix4d::Identity()).cwiseAbs().maxCoeff() > 1e-15) {
            Link l;
            l.name = "END";
            linkElements(m, l, end, prefix, out);
        }
        if (out.empty()) out.push_back({prefix + "BASE", "OFFSET", "", "", Vec3::Zero(), 0.0});
        // Unique names inside the file.
        std::set<std::string> seen;
        for (auto& e : out) {
            std::string n = e.name;
            for (int k = 2; !seen.insert(n).second; ++k) n = fmt::format("{}_{}", e.name, k);
            e.name = n;
        }
    }
    const size_t total = branch[0].size() + branch[1].size() + 1;
    if (static_cast<int>(total) > o.chainMaxElements)
        throw ModelError(fmt::format("siemens-840d: the kinematic chain needs {} elements, more than {}", total,
                                     o.chainMaxElements));
    std::string s = fmt::format("%{}\n;$PATH=/_N_SPF_DIR\n", kChainIdentifier);
    s += header;
    s += fmt::format("; the chain root, named by MD16800 $MN_ROOT_KIN_ELEM_NAME (K7 kinematic chain); NewConfig after loading\n"
                     "{}=\"{}\"\n",
                     kRootMachineData, kRootName);
    s += fmt::format("$NK_NAME[0]=\"{}\"\n$NK_TYPE[0]=\"OFFSET\"\n", kRootName);
    for (int k = 0; k < 3; ++k) s += fmt::format("$NK_OFF_DIR[0,{}]=0\n", k);
    s += fmt::format("$NK_NEXT[0]=\"{}\"\n$NK_PARALLEL[0]=\"{}\"\n", branch[0].front().name, branch[1].front().name);
    int index = 1;
    for (int b = 0; b < 2; ++b) {
        s += b == 0 ? "; tool chain, from ROOT ($NK_NEXT) to the tool reference point\n"
                    : "; part chain, beside it from ROOT ($NK_PARALLEL) to the workpiece (table) reference\n";
        const auto& br = branch[b];
        for (size_t i = 0; i < br.size(); ++i, ++index) {
            const Element& e = br[i];
            s += fmt::format("$NK_NAME[{}]=\"{}\"\n", index, e.name);
            s += fmt::format("$NK_TYPE[{}]=\"{}\"\n", index, e.type);
            if (!e.axis.empty()) s += fmt::format("$NK_AXIS[{}]=\"{}\"\n", index, e.axis);
            const int decimals = e.type == "OFFSET" ? 9 : 15;
            for (int k = 0; k < 3; ++k) s += fmt::format("$NK_OFF_DIR[{},{}]={}\n", index, k, fixed(e.dir[k], decimals));
            if (e.type != "OFFSET" && e.type != "AXIS_LIN") s += fmt::format("$NK_A_OFF[{}]={}\n", index, fixed(e.aOffDeg, 12));
            s += fmt::format("$NK_NEXT[{}]=\"{}\"\n", index, i + 1 < br.size() ? br[i + 1].name : "");
        }
    }
    s += "; transformation record (TRAORI on the chains above)\n";
    s += "$NT_NAME[1]=\"CNCCOMP\"\n$NT_TRAFO_TYPE[1]=\"TRAORI\"\n";
    s += fmt::format("$NT_T_CHAIN_LAST_ELEM[1]=\"{}\"\n", branch[0].back().name);
    s += fmt::format("$NT_P_CHAIN_LAST_ELEM[1]=\"{}\"\n", branch[1].back().name);
    int geo = 0, rot = 0;
    for (int a : controllerAxisOrder(m)) {
        const Link& l = m.axisLink(a);
        const std::string name = (m.axisSide(a) == Side::Tool ? "T_" : "P_") + l.name;
        if (l.kind == AxisKind::Linear && geo < 3) s += fmt::format("$NT_GEO_AX_NAME[1,{}]=\"{}\"\n", geo++, name);
        if (l.kind == AxisKind::Rotary && rot < 3) s += fmt::format("$NT_ROT_AX_NAME[1,{}]=\"{}\"\n", rot++, name);
    }
    s += "M17\n";
    return s;
}

namespace {

struct Raw {
    int line = 0;
    std::optional<std::string> name, next, parallel, type, axis;
    std::optional<double> dir[3], aOff;
};

std::string stringValue(const AssignmentFile& f, const Assignment& a) {
    if (a.kind != Assignment::Kind::String) throw InputError(f.path, a.line, fmt::format("{} needs a \"string\"", a.variable));
    return a.value;
}

}  // namespace

ParsedChain parseKinematicChain(const MachineModel& m, const std::string& path, std::string_view text) {
    const AssignmentFile f = parseAssignmentFile(path, text, kChainIdentifier);
    std::map<int, Raw> raw;
    std::optional<std::string> toolLast, partLast;
    int ntLine = 0;
    std::optional<std::string> rootName;
    int rootLine = 0;
    for (const Assignment& a : f.assignments) {
        const std::string& v = a.variable;
        if (v == kRootMachineData) {
            if (!a.indices.empty()) throw InputError(path, a.line, fmt::format("{} takes no index", v));
            setOnce(rootName, stringValue(f, a), f, a);
            rootLine = a.line;
            continue;
        }
        if (v.starts_with("$NT_")) {
            if (indexNumber(f, a, 0) != 1)
                throw InputError(path, a.line, "only transformation record 1 is written by cnccomp");
            ntLine = a.line;
            if (v == "$NT_T_CHAIN_LAST_ELEM") setOnce(toolLast, stringValue(f, a), f, a);
            else if (v == "$NT_P_CHAIN_LAST_ELEM") setOnce(partLast, stringValue(f, a), f, a);
            else if (v == "$NT_NAME" || v == "$NT_TRAFO_TYPE" || v == "$NT_GEO_AX_NAME" || v == "$NT_ROT_AX_NAME")
                stringValue(f, a);
            else throw InputError(path, a.line, fmt::format("unknown transformation variable {}", v));
            continue;
        }
        if (!v.starts_with("$NK_")) throw InputError(path, a.line, fmt::format("unknown variable {} in a kinematic chain file", v));
        const int e = indexNumber(f, a, 0);
        Raw& r = raw[e];
        if (r.line == 0) r.line = a.line;
        if (v == "$NK_NAME") setOnce(r.name, stringValue(f, a), f, a);
        else if (v == "$NK_NEXT") setOnce(r.next, stringValue(f, a), f, a);
        else if (v == "$NK_PARALLEL") setOnce(r.parallel, stringValue(f, a), f, a);
        else if (v == "$NK_TYPE") setOnce(r.type, stringValue(f, a), f, a);
        else if (v == "$NK_AXIS") setOnce(r.axis, stringValue(f, a), f, a);
        else if (v == "$NK_A_OFF") setOnce(r.aOff, numberValue(f, a), f, a);
        else if (v == "$NK_OFF_DIR") {
            const int k = indexNumber(f, a, 1);
            if (k > 2) throw InputError(path, a.line, "$NK_OFF_DIR component index must be 0, 1 or 2");
            setOnce(r.dir[k], numberValue(f, a), f, a);
        } else {
            throw InputError(path, a.line, fmt::format("unknown chain variable {}", v));
        }
    }
    std::map<std::string, int> byName;
    for (auto& [e, r] : raw) {
        if (!r.name || r.name->empty()) throw InputError(path, r.line, fmt::format("element {} has no $NK_NAME", e));
        if (!r.type) throw InputError(path, r.line, fmt::format("element {} ('{}') has no $NK_TYPE", e, *r.name));
        if (!byName.emplace(*r.name, e).second) throw InputError(path, r.line, fmt::format("element name '{}' used twice", *r.name));
        for (int k = 0; k < 3; ++k)
            if (!r.dir[k]) throw InputError(path, r.line, fmt::format("element '{}' lacks $NK_OFF_DIR[{},{}]", *r.name, e, k));
    }
    // The chain starts at the element MD16800 $MN_ROOT_KIN_ELEM_NAME names (K7).
    if (!rootName || rootName->empty())
        throw InputError(path, rootLine, fmt::format("no {} naming the chain root", kRootMachineData));
    const auto rootIt = byName.find(*rootName);
    if (rootIt == byName.end())
        throw InputError(path, rootLine, fmt::format("{} names '{}', which no $NK_NAME has", kRootMachineData, *rootName));
    const int root = rootIt->second;
    if (!toolLast || !partLast)
        throw InputError(path, ntLine, "missing $NT_T_CHAIN_LAST_ELEM[1] or $NT_P_CHAIN_LAST_ELEM[1]");

    const auto follow = [&](int start) {
        std::vector<int> out;
        std::set<int> seen;
        for (int e = start;;) {
            if (!seen.insert(e).second) throw InputError(path, raw[e].line, fmt::format("the chain loops at '{}'", *raw[e].name));
            out.push_back(e);
            const auto& next = raw[e].next;
            if (!next || next->empty()) break;
            const auto it = byName.find(*next);
            if (it == byName.end())
                throw InputError(path, raw[e].line, fmt::format("$NK_NEXT of '{}' names no element ('{}')", *raw[e].name, *next));
            e = it->second;
        }
        return out;
    };
    const auto& par = raw[root].parallel;
    if (!par || par->empty())
        throw InputError(path, raw[root].line, fmt::format("the root '{}' needs $NK_PARALLEL naming the start of the second chain", *rootName));
    const auto pit = byName.find(*par);
    if (pit == byName.end())
        throw InputError(path, raw[root].line, fmt::format("$NK_PARALLEL of the root names no element ('{}')", *par));
    std::vector<int> a = follow(root), b = follow(pit->second);
    const auto lastName = [&](const std::vector<int>& br) { return *raw[br.back()].name; };
    if (lastName(a) == *partLast && lastName(b) == *toolLast) std::swap(a, b);
    if (lastName(a) != *toolLast || lastName(b) != *partLast)
        throw InputError(path, ntLine, fmt::format("the chains end at '{}' and '{}', but $NT_ names '{}' (tool) and '{}' (part)",
                                                   lastName(a), lastName(b), *toolLast, *partLast));
    for (int e : a)
        for (int g : b)
            if (e == g) throw InputError(path, raw[e].line, "tool and part chains share an element");

    const auto convert = [&](const std::vector<int>& br) {
        std::vector<ChainElement> out;
        for (int e : br) {
            const Raw& r = raw[e];
            const Vec3 dir(*r.dir[0], *r.dir[1], *r.dir[2]);
            const double off = r.aOff.value_or(0.0);
            const std::string& type = *r.type;
            if (type == "OFFSET") {
                Pose p = Pose::Identity();
                p.translation() = dir;
                out.push_back(ChainElement::constant(p));
                continue;
            }
            if (!(dir.norm() > 1e-12)) throw InputError(path, r.line, fmt::format("element '{}' needs a non-zero $NK_OFF_DIR", *r.name));
            const Vec3 u = dir.normalized();
            if (type == "ROT_CONST") {
                Pose p = Pose::Identity();
                p.linear() = axisRotation(u, off * kDeg);
                out.push_back(ChainElement::constant(p));
                continue;
            }
            if (type != "AXIS_LIN" && type != "AXIS_ROT")
                throw InputError(path, r.line, fmt::format("element '{}': type '{}' is not OFFSET, ROT_CONST, AXIS_LIN or AXIS_ROT", *r.name, type));
            if (!r.axis) throw InputError(path, r.line, fmt::format("axis element '{}' has no $NK_AXIS", *r.name));
            Assignment at;
            at.line = r.line;
            at.variable = "$NK_AXIS";
            const int number = axisNumber(f, at, *r.axis);
            const int axis = machineAxisOfNumber(m, number);
            if (axis < 0) throw InputError(path, r.line, fmt::format("machine '{}' has no axis {}", m.name, *r.axis));
            const bool linear = type == "AXIS_LIN";
            if ((m.axisLink(axis).kind == AxisKind::Linear) != linear)
                throw InputError(path, r.line, fmt::format("{} is axis {} of machine '{}', which is {}", *r.axis,
                                                           m.axisNames[axis], m.name, linear ? "rotary" : "linear"));
            Pose p = Pose::Identity();
            if (linear) p.translation() = u * off;
            else p.linear() = axisRotation(u, off * kDeg);
            if (off != 0.0) out.push_back(ChainElement::constant(p));
            out.push_back(ChainElement::motion(axis, u));
        }
        return out;
    };
    ParsedChain pc;
    pc.tool = convert(a);
    pc.workpiece = convert(b);
    return pc;
}

}  // namespace cnccomp::controllers::siemens
