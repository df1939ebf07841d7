#include "cnccomp/io/machine_xml.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <string_view>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/xml_util.hpp"

namespace cnccomp::io {
namespace {

using tinyxml2::XMLElement;

int componentIndex(const XMLElement& e, const std::string& path) {
    static constexpr std::string_view names[] = {"x", "y", "z", "a", "b", "c"};
    const std::string c = xml::text(e, path, "component");
    for (int i = 0; i < 6; ++i)
        if (c == names[i]) return i;
    xml::fail(e, path, fmt::format("component '{}' is not one of x, y, z, a, b, c", c));
}

Link readLink(const XMLElement& e, const std::string& path) {
    Link l;
    l.name = xml::text(e, path, "name");
    const std::string element = e.Name();
    if (element == "fixed") {
        xml::allowAttributes(e, path, {"name", "offset", "rotation"});
        l.kind = AxisKind::Fixed;
    } else if (element == "axis") {
        xml::allowAttributes(e, path, {"name", "type", "direction", "min", "max", "modulo", "machine-zero", "offset", "rotation"});
        const std::string type = xml::text(e, path, "type");
        if (type == "linear") l.kind = AxisKind::Linear;
        else if (type == "rotary") l.kind = AxisKind::Rotary;
        else xml::fail(e, path, fmt::format("type '{}' is not 'linear' or 'rotary'", type));
        const Vec3 dir = xml::vec3(e, path, "direction", Vec3::Zero());
        if (!xml::has(e, "direction")) xml::fail(e, path, "missing attribute 'direction'");
        if (dir.norm() < 1e-12) xml::fail(e, path, "direction must not be zero");
        l.direction = dir.normalized();
        const double unit = l.kind == AxisKind::Rotary ? kDeg : 1.0;
        l.min = xml::number(e, path, "min", -HUGE_VAL) * unit;
        l.max = xml::number(e, path, "max", HUGE_VAL) * unit;
        if (!(l.min <= l.max)) xml::fail(e, path, "min must not exceed max");
        l.modulo = xml::boolean(e, path, "modulo", false);
        if (l.modulo && l.kind != AxisKind::Rotary) xml::fail(e, path, "only a rotary axis can be modulo");
        l.machineZero = xml::number(e, path, "machine-zero", 0.0) * unit;
    } else {
        xml::unknownElement(e, path, {"axis", "fixed"});
    }
    // Nominal placement: offset (mm) then rotation Rz(c)·Ry(b)·Rx(a), angles in degrees.
    const Vec3 off = xml::vec3(e, path, "offset", Vec3::Zero());
    const Vec3 rot = xml::vec3(e, path, "rotation", Vec3::Zero()) * kDeg;
    l.placement = Pose::Identity();
    l.placement.translation() = off;
    l.placement.linear() = (Eigen::AngleAxisd(rot.z(), Vec3::UnitZ()) * Eigen::AngleAxisd(rot.y(), Vec3::UnitY()) *
                            Eigen::AngleAxisd(rot.x(), Vec3::UnitX()))
                               .toRotationMatrix();
    return l;
}

void readChain(const XMLElement* e, const std::string& path, Chain& chain, std::map<std::string, int>& lines) {
    if (!e) return;
    if (std::string(e->Name()) == "tool") xml::allowAttributes(*e, path, {"direction"});
    else xml::allowAttributes(*e, path, {});
    for (const XMLElement* c = e->FirstChildElement(); c; c = c->NextSiblingElement()) {
        chain.links.push_back(readLink(*c, path));
        lines[chain.links.back().name] = c->GetLineNum();
    }
}

ComponentBasis readBasis(const XMLElement& e, const std::string& path, const Link& link) {
    ComponentBasis b;
    const std::string type = xml::text(e, path, "basis");
    const double unit = link.kind == AxisKind::Rotary ? kDeg : 1.0;
    if (type == "polynomial" || type == "fourier") {
        b.type = type == "polynomial" ? ComponentBasis::Type::Polynomial : ComponentBasis::Type::Fourier;
        const double order = xml::number(e, path, "order");
        if (order < 1 || order > 50 || order != std::floor(order)) xml::fail(e, path, "order must be a whole number 1..50");
        b.order = static_cast<int>(order);
        if (b.type == ComponentBasis::Type::Fourier && link.kind != AxisKind::Rotary)
            xml::fail(e, path, "a Fourier basis needs a rotary axis");
    } else if (type == "table") {
        b.type = ComponentBasis::Type::Table;
        for (double v : xml::numbers(e, path, "nodes")) b.nodes.push_back(v * unit);
        if (b.nodes.size() < 2) xml::fail(e, path, "a table needs at least two nodes");
        for (size_t i = 1; i < b.nodes.size(); ++i)
            if (!(b.nodes[i] > b.nodes[i - 1])) xml::fail(e, path, "table nodes must be strictly increasing");
        if (link.modulo && b.nodes.back() - b.nodes.front() >= 2 * kPi - 1e-12)
            xml::fail(e, path, "nodes of a modulo axis must span less than 360 deg (the table closes on itself)");
    } else {
        xml::fail(e, path, fmt::format("basis '{}' is not polynomial, fourier or table", type));
    }
    return b;
}

}  // namespace

MachineModel readMachineXml(const std::string& path) {
    tinyxml2::XMLDocument doc;
    xml::load(doc, path);
    const XMLElement& root = xml::root(doc, path, "machine");
    xml::allowAttributes(root, path, {"name", "description"});
    for (const XMLElement* c = root.FirstChildElement(); c; c = c->NextSiblingElement()) {
        const std::string n = c->Name();
        if (n != "workpiece" && n != "tool" && n != "deviations") xml::unknownElement(*c, path, {"workpiece", "tool", "deviations"});
        if (c->NextSiblingElement(c->Name())) xml::fail(*c->NextSiblingElement(c->Name()), path, fmt::format("a machine has one <{}>", n));
    }
    MachineModel m;
    m.sourceFile = path;
    m.name = xml::text(root, path, "name");
    m.description = xml::textOr(root, "description", "");
    std::map<std::string, int> lines;  // link name → line, for messages after finalize()
    readChain(root.FirstChildElement("workpiece"), path, m.workpiece, lines);
    const XMLElement* tool = root.FirstChildElement("tool");
    if (!tool) xml::fail(root, path, "missing <tool> chain");
    readChain(tool, path, m.tool, lines);
    const Vec3 td = xml::vec3(*tool, path, "direction", -Vec3::UnitZ());
    if (td.norm() < 1e-12) xml::fail(*tool, path, "tool direction must not be zero");
    m.toolDirection = td.normalized();

    if (const XMLElement* devs = root.FirstChildElement("deviations")) {
        xml::allowAttributes(*devs, path, {});
        for (const XMLElement* e = devs->FirstChildElement(); e; e = e->NextSiblingElement()) {
            DeviationDef d;
            const std::string kind = e->Name();
            if (kind == "location") d.kind = DeviationKind::Location;
            else if (kind == "component") d.kind = DeviationKind::Component;
            else xml::unknownElement(*e, path, {"location", "component"});
            if (d.kind == DeviationKind::Location)
                xml::allowAttributes(*e, path, {"name", "alias", "alias-sign", "description", "link", "component"});
            else
                xml::allowAttributes(*e, path, {"name", "alias", "alias-sign", "description", "link", "component", "basis",
                                                "order", "nodes"});
            d.name = xml::text(*e, path, "name");
            d.alias = xml::textOr(*e, "alias", "");
            const std::string sign = xml::textOr(*e, "alias-sign", "+1");
            if (sign == "+1" || sign == "1") d.aliasSign = 1.0;
            else if (sign == "-1") d.aliasSign = -1.0;
            else xml::fail(*e, path, fmt::format("alias-sign '{}': expected +1 or -1", sign));
            if (d.alias.empty() && e->Attribute("alias-sign")) xml::fail(*e, path, "alias-sign without an alias");
            d.description = xml::textOr(*e, "description", "");
            const std::string link = xml::text(*e, path, "link");
            bool found = false;
            for (Side s : {Side::Workpiece, Side::Tool}) {
                const Chain& c = m.chain(s);
                for (int i = 0; i < static_cast<int>(c.links.size()); ++i)
                    if (c.links[i].name == link) {
                        if (found) xml::fail(*e, path, fmt::format("link name '{}' is ambiguous", link));
                        d.side = s;
                        d.link = i;
                        found = true;
                    }
            }
            if (!found) xml::fail(*e, path, fmt::format("no link named '{}' in the chains", link));
            d.component = componentIndex(*e, path);
            if (d.kind == DeviationKind::Component) {
                const Link& l = m.chain(d.side).links[d.link];
                if (l.kind == AxisKind::Fixed) xml::fail(*e, path, "a component error needs a moving axis");
                d.basis = readBasis(*e, path, l);
            }
            m.deviations.push_back(std::move(d));
        }
    }
    try {
        m.finalize();
    } catch (const ModelError& ex) {
        throw InputError(path, root.GetLineNum(), ex.what());
    }
    // X, Y and Z are the machine's three primary linear axes, at right angles (ISO 841:2001 §4.3: the right-handed
    // rectangular system). Two of them (nearly) parallel is a typing mistake in `direction` or `rotation`; secondary
    // axes (U, V, W, ... along X, Y, Z) may be parallel to them. Inclined axes exist (a lathe's Y at 60-75° to X),
    // so only less than 10° apart is refused [G: the bound is ours].
    for (int a = 0; a < m.axisCount(); ++a)
        for (int b = 0; b < a; ++b) {
            const auto primary = [&](int i) {
                const std::string& n = m.axisNames[static_cast<size_t>(i)];
                return m.axisLink(i).kind == AxisKind::Linear && (n == "X" || n == "Y" || n == "Z");
            };
            if (!primary(a) || !primary(b)) continue;
            const double sine = m.nominalDirection(a).cross(m.nominalDirection(b)).norm();
            if (sine < std::sin(10 * kDeg))
                throw InputError(path, lines[m.axisNames[static_cast<size_t>(a)]],
                                 fmt::format("axes {} and {} are parallel ({:.2f} deg apart in the bed frame); X, Y and Z "
                                             "must move in three different directions (check direction and rotation)",
                                             m.axisNames[static_cast<size_t>(b)], m.axisNames[static_cast<size_t>(a)],
                                             std::asin(std::min(1.0, sine)) / kDeg));
        }
    return m;
}

}  // namespace cnccomp::io
