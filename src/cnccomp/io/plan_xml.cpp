#include "cnccomp/io/plan_xml.hpp"

#include <ostream>
#include <set>
#include <sstream>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/text_util.hpp"
#include "cnccomp/io/xml_util.hpp"

namespace cnccomp {

namespace {

using tinyxml2::XMLElement;

BallbarRun readBallbarRun(const XMLElement& e, const std::string& path, bool absolute) {
    BallbarRun r;
    r.name = xml::text(e, path, "name");
    const std::string test = xml::text(e, path, "test");
    const auto t = parseTest(test);
    if (!t)
        xml::fail(e, path, fmt::format("unknown test '{}'; expected one of B-X B-Y B-Z C-radial C-tangential "
                                       "C-axial C-X C-Y C-Z B-radial B-tangential B-axial",
                                       test));
    r.test = *t;
    r.LB = xml::number(e, path, "LB");
    r.RB = xml::number(e, path, "RB");
    r.RC = xml::number(e, path, "RC", 0.0);
    r.ZC = xml::number(e, path, "ZC");
    r.startDeg = xml::number(e, path, "start", 0.0);
    r.endDeg = xml::number(e, path, "end", 360.0);
    r.stepDeg = xml::number(e, path, "step", 1.0);
    r.toolBallOffset = xml::vec3(e, path, "tool-ball-offset", Vec3::Zero());
    r.workBallOffset = xml::vec3(e, path, "work-ball-offset", Vec3::Zero());
    const std::string est = xml::textOr(e, "estimate-mounting", "none");
    if (absolute && est != "none" && est != "work")
        xml::fail(e, path, fmt::format("estimate-mounting '{}': an absolute run takes none or work", est));
    if (est != "none" && est != "tool" && est != "work" && est != "both")
        xml::fail(e, path, fmt::format("estimate-mounting '{}' is not none, tool, work or both", est));
    r.estimateToolBallOffset = est == "tool" || est == "both";
    r.estimateWorkBallOffset = est == "work" || est == "both";
    r.headAxis = xml::textOr(e, "head-axis", "B");
    r.tableAxis = xml::textOr(e, "table-axis", "C");
    try {
        r.validate();
    } catch (const ModelError& ex) {
        xml::fail(e, path, ex.what());
    }
    return r;
}

/// <hold axis deg/> and (R-test) <sweep axis start end/> children.
void readAxisChildren(const XMLElement& e, const std::string& path, bool sweeps, std::vector<RotarySweep>& out) {
    for (const XMLElement* c = e.FirstChildElement(); c; c = c->NextSiblingElement()) {
        const std::string n = c->Name();
        RotarySweep s;
        s.axis = xml::text(*c, path, "axis");
        if (n == "hold") {
            s.startDeg = s.endDeg = xml::number(*c, path, "deg");
        } else if (n == "sweep" && sweeps) {
            s.startDeg = xml::number(*c, path, "start");
            s.endDeg = xml::number(*c, path, "end");
        } else {
            xml::fail(*c, path, sweeps ? "expected <sweep> or <hold>" : "expected <hold>");
        }
        for (const RotarySweep& o : out)
            if (o.axis == s.axis) xml::fail(*c, path, fmt::format("axis '{}' is given twice", s.axis));
        out.push_back(s);
    }
}

int wholeNumber(const XMLElement& e, const std::string& path, const char* attr, int fallback) {
    const double v = xml::number(e, path, attr, fallback);
    if (v != std::floor(v) || v < 1 || v > 1e6) xml::fail(e, path, fmt::format("'{}' must be a whole number 1 .. 1000000", attr));
    return static_cast<int>(v);
}

RtestRun readRtestRun(const XMLElement& e, const std::string& path) {
    RtestRun r;
    r.name = xml::text(e, path, "name");
    if (!xml::has(e, "ball")) xml::fail(e, path, "missing attribute 'ball'");
    r.ball = xml::vec3(e, path, "ball", Vec3::Zero());
    r.nestLength = xml::number(e, path, "nest-length", 100.0);
    r.steps = wholeNumber(e, path, "steps", 36);
    r.ballOffset = xml::vec3(e, path, "ball-offset", Vec3::Zero());
    r.estimateBall = xml::boolean(e, path, "estimate-ball", false);
    readAxisChildren(e, path, true, r.sweeps);
    try {
        r.validate();
    } catch (const ModelError& ex) {
        xml::fail(e, path, ex.what());
    }
    return r;
}

Dbb5Run readDbb5Run(const XMLElement& e, const std::string& path) {
    Dbb5Run r;
    r.name = xml::text(e, path, "name");
    const std::string kind = xml::text(e, path, "kind");
    if (kind == "linear") r.kind = Dbb5Run::Kind::LinearCircle;
    else if (kind == "rotary") r.kind = Dbb5Run::Kind::RotaryCircle;
    else if (kind == "cone") r.kind = Dbb5Run::Kind::ConeFrustum;
    else xml::fail(e, path, fmt::format("kind '{}' is not linear, rotary or cone", kind));
    r.LB = xml::number(e, path, "LB");
    r.toolLength = xml::number(e, path, "tool-length", 100.0);
    if (!xml::has(e, "ball")) xml::fail(e, path, "missing attribute 'ball'");
    r.ball = xml::vec3(e, path, "ball", Vec3::Zero());
    r.startDeg = xml::number(e, path, "start", 0.0);
    r.endDeg = xml::number(e, path, "end", 360.0);
    r.stepDeg = xml::number(e, path, "step", 5.0);
    if (r.kind == Dbb5Run::Kind::LinearCircle) {
        r.plane = xml::text(e, path, "plane");
    } else if (r.kind == Dbb5Run::Kind::ConeFrustum) {
        r.coneTiltDeg = xml::number(e, path, "cone-tilt", 10.0);
        r.toolAngleDeg = xml::number(e, path, "tool-angle", 15.0);
        r.barAngleDeg = xml::number(e, path, "bar-angle", 45.0);
        r.setupDeg = xml::number(e, path, "setup", 0.0);
    } else {
        r.axis = xml::text(e, path, "axis");
        if (!xml::has(e, "direction")) xml::fail(e, path, "missing attribute 'direction' (table ball → spindle ball)");
        r.barDirection = xml::vec3(e, path, "direction", Vec3::Zero());
        r.setupDeg = xml::number(e, path, "setup", 0.0);
        if (r.barDirection.norm() > 0) r.barDirection.normalize();
    }
    std::vector<RotarySweep> holds;
    readAxisChildren(e, path, false, holds);
    for (const RotarySweep& h : holds) {
        if (r.kind == Dbb5Run::Kind::RotaryCircle && h.axis == r.axis)
            xml::fail(e, path, fmt::format("axis '{}' turns in this run and cannot be held", h.axis));
        r.hold.emplace_back(h.axis, h.startDeg);
    }
    try {
        r.validate();
    } catch (const ModelError& ex) {
        xml::fail(e, path, ex.what());
    }
    return r;
}

std::string vec(const Vec3& v) {  // + 0.0 prints −0 as 0
    return fmt::format("{:g} {:g} {:g}", v.x() + 0.0, v.y() + 0.0, v.z() + 0.0);
}

void formatBallbar(std::ostream& o, const char* element, const BallbarRun& r) {
    o << fmt::format("  <{} name=\"{}\" test=\"{}\" LB=\"{:g}\" RB=\"{:g}\" RC=\"{:g}\" ZC=\"{:g}\" start=\"{:g}\" "
                     "end=\"{:g}\" step=\"{:g}\"",
                     element, r.name, testName(r.test), r.LB, r.RB, r.RC, r.ZC, r.startDeg, r.endDeg, r.stepDeg);
    if (!r.toolBallOffset.isZero()) o << fmt::format(" tool-ball-offset=\"{}\"", vec(r.toolBallOffset));
    if (!r.workBallOffset.isZero()) o << fmt::format(" work-ball-offset=\"{}\"", vec(r.workBallOffset));
    if (r.estimateToolBallOffset || r.estimateWorkBallOffset)
        o << fmt::format(" estimate-mounting=\"{}\"", r.estimateToolBallOffset && r.estimateWorkBallOffset ? "both"
                                                       : r.estimateToolBallOffset                             ? "tool"
                                                                                                              : "work");
    if (r.headAxis != "B") o << fmt::format(" head-axis=\"{}\"", r.headAxis);
    if (r.tableAxis != "C") o << fmt::format(" table-axis=\"{}\"", r.tableAxis);
    o << "/>\n";
}

}  // namespace

MeasurementPlan readPlanXml(const std::string& path) {
    tinyxml2::XMLDocument doc;
    xml::load(doc, path);
    const auto& root = xml::root(doc, path, "plan");
    MeasurementPlan plan;
    plan.machine = xml::textOr(root, "machine", "");
    plan.description = xml::textOr(root, "description", "");
    std::set<std::string> names;
    for (const auto* e = root.FirstChildElement(); e; e = e->NextSiblingElement()) {
        const std::string kind = e->Name();
        std::string name;
        if (kind == "run") {
            plan.runs.push_back(readBallbarRun(*e, path, false));
            name = plan.runs.back().name;
        } else if (kind == "absolute-run") {
            plan.absoluteRuns.push_back(readBallbarRun(*e, path, true));
            name = plan.absoluteRuns.back().name;
        } else if (kind == "rtest") {
            plan.rtestRuns.push_back(readRtestRun(*e, path));
            name = plan.rtestRuns.back().name;
        } else if (kind == "dbb5") {
            plan.dbb5Runs.push_back(readDbb5Run(*e, path));
            name = plan.dbb5Runs.back().name;
        } else {
            xml::fail(*e, path, "expected <run>, <absolute-run>, <rtest> or <dbb5>");
        }
        if (!names.insert(name).second) xml::fail(*e, path, fmt::format("run name '{}' is used twice", name));
    }
    if (plan.runCount() == 0) xml::fail(root, path, "a plan needs at least one run (<run>, <absolute-run>, <rtest> or <dbb5>)");
    return plan;
}

std::string formatPlanXml(const MeasurementPlan& plan) {
    std::ostringstream o;
    o << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
    o << fmt::format("<plan machine=\"{}\" description=\"{}\">\n", plan.machine, plan.description);
    for (const auto& r : plan.runs) formatBallbar(o, "run", r);
    for (const auto& r : plan.absoluteRuns) formatBallbar(o, "absolute-run", r);
    for (const auto& r : plan.rtestRuns) {
        o << fmt::format("  <rtest name=\"{}\" ball=\"{}\" nest-length=\"{:g}\" steps=\"{}\"", r.name, vec(r.ball),
                         r.nestLength, r.steps);
        if (!r.ballOffset.isZero()) o << fmt::format(" ball-offset=\"{}\"", vec(r.ballOffset));
        if (r.estimateBall) o << " estimate-ball=\"true\"";
        o << ">\n";
        for (const RotarySweep& s : r.sweeps) {
            if (s.startDeg == s.endDeg) o << fmt::format("    <hold axis=\"{}\" deg=\"{:g}\"/>\n", s.axis, s.startDeg);
            else o << fmt::format("    <sweep axis=\"{}\" start=\"{:g}\" end=\"{:g}\"/>\n", s.axis, s.startDeg, s.endDeg);
        }
        o << "  </rtest>\n";
    }
    for (const auto& r : plan.dbb5Runs) {
        const bool linear = r.kind == Dbb5Run::Kind::LinearCircle, cone = r.kind == Dbb5Run::Kind::ConeFrustum;
        o << fmt::format("  <dbb5 name=\"{}\" kind=\"{}\" LB=\"{:g}\" tool-length=\"{:g}\" ball=\"{}\" start=\"{:g}\" "
                         "end=\"{:g}\" step=\"{:g}\"",
                         r.name, linear ? "linear" : cone ? "cone" : "rotary", r.LB, r.toolLength, vec(r.ball), r.startDeg,
                         r.endDeg, r.stepDeg);
        if (linear) o << fmt::format(" plane=\"{}\"", r.plane);
        else if (cone)
            o << fmt::format(" cone-tilt=\"{:g}\" tool-angle=\"{:g}\" bar-angle=\"{:g}\" setup=\"{:g}\"", r.coneTiltDeg,
                             r.toolAngleDeg, r.barAngleDeg, r.setupDeg);
        else o << fmt::format(" axis=\"{}\" direction=\"{}\" setup=\"{:g}\"", r.axis, vec(r.barDirection), r.setupDeg);
        if (r.hold.empty()) {
            o << "/>\n";
            continue;
        }
        o << ">\n";
        for (const auto& [axis, deg] : r.hold) o << fmt::format("    <hold axis=\"{}\" deg=\"{:g}\"/>\n", axis, deg);
        o << "  </dbb5>\n";
    }
    o << "</plan>\n";
    return o.str();
}

void writePlanXml(const std::string& path, const MeasurementPlan& plan) {
    const std::string text = formatPlanXml(plan);
    writeFileAtomically(path, [&](std::ostream& o) { o << text; });
}

}  // namespace cnccomp
