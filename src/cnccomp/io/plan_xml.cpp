#include "cnccomp/io/plan_xml.hpp"

#include <cmath>
#include <ostream>
#include <set>
#include <sstream>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/markup.hpp"
#include "cnccomp/io/output_set.hpp"
#include "cnccomp/io/text_util.hpp"
#include "cnccomp/io/xml_util.hpp"

namespace cnccomp::io {
using namespace cnccomp::measurement;

namespace {

using tinyxml2::XMLElement;

// --- measured runs: <instrument> and the capture attributes of <run> (RunCapture) -------------------------------

struct UnitName {
    const char* name;
    double value;
};
constexpr UnitName kLengthUnits[] = {{"um", 1e-3}, {"µm", 1e-3}, {"mm", 1.0}, {"nm", 1e-6}, {"in", 25.4}};
constexpr UnitName kAngleUnits[] = {{"deg", 1.0}, {"rad", 180.0 / M_PI}};
constexpr UnitName kTimeUnits[] = {{"s", 1.0}, {"ms", 1e-3}};

template <size_t N>
void readUnit(const XMLElement& e, const std::string& path, const char* attr, const UnitName (&units)[N], double& out) {
    if (!xml::has(e, attr)) return;
    const std::string v = xml::text(e, path, attr);
    std::string known;
    for (const UnitName& u : units) {
        if (v == u.name) {
            out = u.value;
            return;
        }
        known += known.empty() ? u.name : std::string(", ") + u.name;
    }
    xml::fail(e, path, fmt::format("{} '{}' is not one of {}", attr, v, known));
}

template <size_t N>
const char* unitName(double value, const UnitName (&units)[N]) {
    for (const UnitName& u : units)
        if (u.value == value) return u.name;
    return units[0].name;
}

std::string choice(const XMLElement& e, const std::string& path, const char* attr, std::initializer_list<const char*> allowed) {
    const std::string v = xml::text(e, path, attr);
    std::string list;
    for (const char* a : allowed) {
        if (v == a) return v;
        list += list.empty() ? a : std::string(", ") + a;
    }
    xml::fail(e, path, fmt::format("{} '{}' is not one of {}", attr, v, list));
}

/// The instrument part of a capture (<instrument> or the same attributes on a run).
void readInstrument(const XMLElement& e, const std::string& path, RunCapture& c) {
    for (auto [attr, field] : {std::pair{"angle-column", &c.angleColumn}, {"time-column", &c.timeColumn},
                               {"length-column", &c.lengthColumn}, {"pass-column", &c.passColumn}})
        if (xml::has(e, attr)) {
            *field = xml::text(e, path, attr);
            if (field->empty() || field->find_first_of(",;\t\"") != std::string::npos)
                xml::fail(e, path, fmt::format("{} '{}' must be a non-empty column name without , ; tab or \"", attr, *field));
        }
    readUnit(e, path, "length-unit", kLengthUnits, c.lengthUnit);
    readUnit(e, path, "angle-unit", kAngleUnits, c.angleUnit);
    readUnit(e, path, "time-unit", kTimeUnits, c.timeUnit);
    if (xml::has(e, "decimal")) {
        const std::string d = choice(e, path, "decimal", {"auto", "point", "comma"});
        c.decimal = d == "point" ? '.' : d == "comma" ? ',' : 0;
    }
    if (xml::has(e, "length")) c.relativeLength = choice(e, path, "length", {"absolute", "relative"}) == "relative";
    if (xml::has(e, "drift")) c.removeDrift = choice(e, path, "drift", {"keep", "remove"}) == "remove";
}

void readCapture(const XMLElement& e, const std::string& path, const RunCapture& instrument, RunCapture& c) {
    c = instrument;
    readInstrument(e, path, c);
    c.feed = xml::number(e, path, "feed", 0.0);
    c.feedRadius = xml::number(e, path, "feed-radius", 0.0);
    c.overshootDeg = xml::number(e, path, "overshoot", 0.0);
    if (!(c.feed >= 0) || !std::isfinite(c.feed)) xml::fail(e, path, "feed must be a non-negative number (mm/min)");
    if (!(c.feedRadius >= 0) || !std::isfinite(c.feedRadius)) xml::fail(e, path, "feed-radius must be a non-negative number (mm)");
    if (!(c.overshootDeg >= 0) || !(c.overshootDeg < 360)) xml::fail(e, path, "overshoot must be 0 .. 360 deg");
    if (xml::has(e, "directions")) {
        std::istringstream in(xml::text(e, path, "directions"));
        std::string w;
        while (in >> w) {
            if (w == "ccw" || w == "CCW") c.passes.push_back(+1);
            else if (w == "cw" || w == "CW") c.passes.push_back(-1);
            else xml::fail(e, path, fmt::format("directions: '{}' is not ccw or cw", w));
        }
        if (c.passes.empty() || c.passes.size() > 2 || (c.passes.size() == 2 && c.passes[0] == c.passes[1]))
            xml::fail(e, path, "directions must be \"ccw\", \"cw\", \"ccw cw\" or \"cw ccw\"");
    }
}

/// Attributes of the instrument part that differ from `base`.
std::string instrumentAttributes(const RunCapture& c, const RunCapture& base) {
    std::string o;
    const auto text = [&](const char* attr, const std::string& v, const std::string& b) {
        if (v != b) o += fmt::format(" {}=\"{}\"", attr, escapeXml(v, attr));
    };
    text("angle-column", c.angleColumn, base.angleColumn);
    text("time-column", c.timeColumn, base.timeColumn);
    text("length-column", c.lengthColumn, base.lengthColumn);
    text("pass-column", c.passColumn, base.passColumn);
    if (c.lengthUnit != base.lengthUnit) o += fmt::format(" length-unit=\"{}\"", unitName(c.lengthUnit, kLengthUnits));
    if (c.angleUnit != base.angleUnit) o += fmt::format(" angle-unit=\"{}\"", unitName(c.angleUnit, kAngleUnits));
    if (c.timeUnit != base.timeUnit) o += fmt::format(" time-unit=\"{}\"", unitName(c.timeUnit, kTimeUnits));
    if (c.decimal != base.decimal)
        o += fmt::format(" decimal=\"{}\"", c.decimal == '.' ? "point" : c.decimal == ',' ? "comma" : "auto");
    if (c.relativeLength != base.relativeLength) o += fmt::format(" length=\"{}\"", c.relativeLength ? "relative" : "absolute");
    if (c.removeDrift != base.removeDrift) o += fmt::format(" drift=\"{}\"", c.removeDrift ? "remove" : "keep");
    return o;
}

RunCapture instrumentPart(RunCapture c) {
    const RunCapture d;
    c.feed = d.feed;
    c.feedRadius = d.feedRadius;
    c.overshootDeg = d.overshootDeg;
    c.passes = d.passes;
    return c;
}

std::string captureAttributes(const RunCapture& c, const RunCapture& instrument) {
    std::string o;
    if (c.feed != 0) o += fmt::format(" feed=\"{:g}\"", c.feed);
    if (c.feedRadius != 0) o += fmt::format(" feed-radius=\"{:g}\"", c.feedRadius);
    if (c.overshootDeg != 0) o += fmt::format(" overshoot=\"{:g}\"", c.overshootDeg);
    if (!c.passes.empty()) {
        o += " directions=\"";
        for (size_t i = 0; i < c.passes.size(); ++i) o += fmt::format("{}{}", i ? " " : "", c.passes[i] > 0 ? "ccw" : "cw");
        o += "\"";
    }
    return o + instrumentAttributes(c, instrument);
}

/// A run's name names its data file DIR/<name>.csv: it must be a plain file name.
std::string runName(const XMLElement& e, const std::string& path) {
    std::string name = xml::text(e, path, "name");
    if (const std::string why = fileNameProblem(name); !why.empty())
        xml::fail(e, path, fmt::format("run name '{}' cannot name its data file <name>.csv: {}", name, why));
    return name;
}

BallbarRun readBallbarRun(const XMLElement& e, const std::string& path, bool absolute, const RunCapture& instrument) {
    xml::allowAttributes(e, path, {"name", "test", "LB", "RB", "RC", "ZC", "start", "end", "step", "tool-ball-offset",
                                   "work-ball-offset", "estimate-mounting", "head-axis", "table-axis", "feed", "feed-radius",
                                   "overshoot", "directions", "angle-column", "time-column", "length-column", "pass-column",
                                   "length-unit", "angle-unit", "time-unit", "decimal", "length", "drift"});
    if (e.FirstChildElement()) xml::fail(*e.FirstChildElement(), path, fmt::format("<{}> takes no child elements", e.Name()));
    BallbarRun r;
    r.name = runName(e, path);
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
    readCapture(e, path, instrument, r.capture);
    if (absolute && r.capture.relativeLength)
        xml::fail(e, path, "an absolute run measures the absolute length ([FanWuLi]); its instrument cannot be length=\"relative\"");
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
            xml::allowAttributes(*c, path, {"axis", "deg"});
            s.startDeg = s.endDeg = xml::number(*c, path, "deg");
        } else if (n == "sweep" && sweeps) {
            xml::allowAttributes(*c, path, {"axis", "start", "end"});
            s.startDeg = xml::number(*c, path, "start");
            s.endDeg = xml::number(*c, path, "end");
        } else if (sweeps) {
            xml::unknownElement(*c, path, {"sweep", "hold"});
        } else {
            xml::unknownElement(*c, path, {"hold"});
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
    xml::allowAttributes(e, path, {"name", "ball", "nest-length", "steps", "ball-offset", "estimate-ball"});
    RtestRun r;
    r.name = runName(e, path);
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

/// <sweep>/<hold> children of a <sphere> or its <group>.
void readSphereAxes(const XMLElement& c, const std::string& path, std::vector<RotarySweep>& out) {
    const std::string n = c.Name();
    RotarySweep s;
    s.axis = xml::text(c, path, "axis");
    if (n == "hold") {
        xml::allowAttributes(c, path, {"axis", "deg"});
        s.startDeg = s.endDeg = xml::number(c, path, "deg");
    } else {
        xml::allowAttributes(c, path, {"axis", "start", "end"});
        s.startDeg = xml::number(c, path, "start");
        s.endDeg = xml::number(c, path, "end");
    }
    for (const RotarySweep& o : out)
        if (o.axis == s.axis) xml::fail(c, path, fmt::format("axis '{}' is given twice", s.axis));
    out.push_back(s);
}

SphereRun readSphereRun(const XMLElement& e, const std::string& path) {
    xml::allowAttributes(e, path, {"name", "centre", "diameter", "stylus-diameter", "tool-length", "approach", "feed",
                                   "clearance", "window", "latitude", "ring", "trigger-offset", "estimate-trigger", "steps",
                                   "sphere-offset", "trigger-error"});
    SphereRun r;
    r.name = runName(e, path);
    r.line = e.GetLineNum();
    for (const char* a : {"centre", "diameter", "stylus-diameter"})
        if (!xml::has(e, a)) xml::fail(e, path, fmt::format("missing attribute '{}'", a));
    r.centre = xml::vec3(e, path, "centre", Vec3::Zero());
    r.diameter = xml::number(e, path, "diameter");
    r.stylusDiameter = xml::number(e, path, "stylus-diameter");
    r.toolLength = xml::number(e, path, "tool-length", r.toolLength);
    r.approach = xml::number(e, path, "approach", r.approach);
    r.feed = xml::number(e, path, "feed", r.feed);
    r.clearance = xml::number(e, path, "clearance", r.clearance);
    if (xml::has(e, "window")) r.window = xml::number(e, path, "window");
    r.latitudeDeg = xml::number(e, path, "latitude", r.latitudeDeg);
    const double ring = xml::number(e, path, "ring", r.ringTouches);
    if (ring != std::floor(ring) || ring < 4 || ring > 64) xml::fail(e, path, "'ring' must be a whole number 4 .. 64");
    r.ringTouches = static_cast<int>(ring);
    r.triggerOffset = xml::number(e, path, "trigger-offset", 0.0);
    r.estimateTrigger = xml::boolean(e, path, "estimate-trigger", true);
    r.sphereOffset = xml::vec3(e, path, "sphere-offset", Vec3::Zero());
    r.triggerError = xml::number(e, path, "trigger-error", 0.0);
    SpherePoseGroup direct;
    direct.line = e.GetLineNum();
    bool hasDirect = false;
    for (const XMLElement* c = e.FirstChildElement(); c; c = c->NextSiblingElement()) {
        const std::string n = c->Name();
        if (n == "sweep" || n == "hold") {
            readSphereAxes(*c, path, direct.sweeps);
            hasDirect = true;
        } else if (n == "group") {
            xml::allowAttributes(*c, path, {"steps"});
            SpherePoseGroup g;
            g.line = c->GetLineNum();
            g.steps = wholeNumber(*c, path, "steps", 8);
            for (const XMLElement* d = c->FirstChildElement(); d; d = d->NextSiblingElement()) {
                const std::string dn = d->Name();
                if (dn != "sweep" && dn != "hold") xml::unknownElement(*d, path, {"sweep", "hold"});
                readSphereAxes(*d, path, g.sweeps);
            }
            bool moving = false;
            for (const RotarySweep& s : g.sweeps) moving = moving || s.startDeg != s.endDeg;
            if (!moving) xml::fail(*c, path, "a <group> needs a <sweep> whose start and end differ");
            r.groups.push_back(g);
        } else if (n == "pose") {
            SpherePoseGroup g;
            g.line = c->GetLineNum();
            for (const tinyxml2::XMLAttribute* a = c->FirstAttribute(); a; a = a->Next()) {
                RotarySweep s;
                s.axis = a->Name();
                const auto v = parseNumber(a->Value());
                if (!v || !std::isfinite(*v))
                    xml::fail(*c, path, fmt::format("<pose> {}=\"{}\": expected an angle in degrees", s.axis, a->Value()));
                s.startDeg = s.endDeg = *v;
                g.sweeps.push_back(s);
            }
            if (g.sweeps.empty()) xml::fail(*c, path, "a <pose> names the rotary axes' angles, e.g. <pose A=\"30\" C=\"90\"/>");
            r.groups.push_back(g);
        } else {
            xml::unknownElement(*c, path, {"sweep", "hold", "group", "pose"});
        }
    }
    if (hasDirect) {
        bool moving = false;
        for (const RotarySweep& s : direct.sweeps) moving = moving || s.startDeg != s.endDeg;
        direct.steps = moving ? wholeNumber(e, path, "steps", 8) : 0;
        r.groups.insert(r.groups.begin(), direct);
    } else if (xml::has(e, "steps")) {
        xml::fail(e, path, "'steps' applies to <sweep> children of <sphere> (a <group> has its own)");
    }
    try {
        r.validate();
    } catch (const ModelError& ex) {
        xml::fail(e, path, ex.what());
    }
    return r;
}

Dbb5Run readDbb5Run(const XMLElement& e, const std::string& path) {
    xml::allowAttributes(e, path, {"name", "kind", "LB", "tool-length", "ball", "start", "end", "step", "plane", "cone-tilt",
                                   "tool-angle", "bar-angle", "setup", "axis", "direction"});
    Dbb5Run r;
    r.name = runName(e, path);
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

LinearCircleRun readCircleRun(const XMLElement& e, const std::string& path, const RunCapture& instrument) {
    xml::allowAttributes(e, path, {"name", "plane", "centre", "radius", "start", "arc", "step", "tool-length", "pivot-offset", "pitch",
                                   "date", "instrument", "operator", "feed", "overshoot", "directions", "angle-column",
                                   "time-column", "length-column", "pass-column", "length-unit", "angle-unit", "time-unit",
                                   "decimal", "length", "drift"});
    LinearCircleRun r;
    r.name = runName(e, path);
    r.line = e.GetLineNum();
    const std::string plane = xml::text(e, path, "plane");
    if (plane == "XY") r.plane = LinearPlane::XY;
    else if (plane == "YZ") r.plane = LinearPlane::YZ;
    else if (plane == "ZX") r.plane = LinearPlane::ZX;
    else
        xml::fail(e, path, fmt::format("plane '{}' is not XY, YZ or ZX (the first axis is u, θ = 0 along it; YX, ZY and XZ "
                                       "are the same planes written the other way: use XY, YZ, ZX)",
                                       plane));
    if (!xml::has(e, "radius")) xml::fail(e, path, "missing attribute 'radius' (mm, the ball-bar length)");
    r.radius = xml::number(e, path, "radius");
    r.centre = xml::vec3(e, path, "centre", Vec3::Zero());
    r.startDeg = xml::number(e, path, "start", 0.0);
    r.arcDeg = xml::number(e, path, "arc", 360.0);
    r.stepDeg = xml::number(e, path, "step", 1.0);
    r.toolLength = xml::number(e, path, "tool-length", 0.0);
    r.pivotOffset = xml::vec3(e, path, "pivot-offset", Vec3::Zero());
    if (xml::has(e, "pitch")) {
        std::istringstream in(xml::text(e, path, "pitch"));
        double a = 0, b = 0;
        std::string rest;
        if (!(in >> a >> b) || (in >> rest))
            xml::fail(e, path, "pitch must be two numbers \"pu pv\" (mm; 0 = no cyclic error estimated for that axis)");
        r.cyclicPitch = {a, b};
    }
    r.date = xml::textOr(e, "date", "");
    r.instrument = xml::textOr(e, "instrument", "");
    r.operatorName = xml::textOr(e, "operator", "");
    readCapture(e, path, instrument, r.capture);
    if (!xml::has(e, "feed")) r.capture.feed = 1000.0;
    if (r.capture.passes.empty()) r.capture.passes = {-1, +1};
    std::vector<RotarySweep> holds;
    readAxisChildren(e, path, false, holds);
    for (const RotarySweep& h : holds) r.hold.emplace_back(h.axis, h.startDeg);
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

std::string esc(const std::string& s) { return escapeXml(s, "plan text"); }

void formatBallbar(std::ostream& o, const char* element, const BallbarRun& r, const RunCapture& instrument) {
    o << fmt::format("  <{} name=\"{}\" test=\"{}\" LB=\"{:g}\" RB=\"{:g}\" RC=\"{:g}\" ZC=\"{:g}\" start=\"{:g}\" "
                     "end=\"{:g}\" step=\"{:g}\"",
                     element, esc(r.name), testName(r.test), r.LB, r.RB, r.RC, r.ZC, r.startDeg, r.endDeg, r.stepDeg);
    if (!r.toolBallOffset.isZero()) o << fmt::format(" tool-ball-offset=\"{}\"", vec(r.toolBallOffset));
    if (!r.workBallOffset.isZero()) o << fmt::format(" work-ball-offset=\"{}\"", vec(r.workBallOffset));
    if (r.estimateToolBallOffset || r.estimateWorkBallOffset)
        o << fmt::format(" estimate-mounting=\"{}\"", r.estimateToolBallOffset && r.estimateWorkBallOffset ? "both"
                                                       : r.estimateToolBallOffset                             ? "tool"
                                                                                                              : "work");
    if (r.headAxis != "B") o << fmt::format(" head-axis=\"{}\"", esc(r.headAxis));
    if (r.tableAxis != "C") o << fmt::format(" table-axis=\"{}\"", esc(r.tableAxis));
    o << captureAttributes(r.capture, instrument);
    o << "/>\n";
}

}  // namespace

MeasurementPlan readPlanXml(const std::string& path) {
    tinyxml2::XMLDocument doc;
    xml::load(doc, path);
    const auto& root = xml::root(doc, path, "plan");
    xml::allowAttributes(root, path, {"machine", "description", "noise-um"});
    MeasurementPlan plan;
    plan.machine = xml::textOr(root, "machine", "");
    plan.description = xml::textOr(root, "description", "");
    plan.line = root.GetLineNum();
    if (root.Attribute("noise-um")) {
        plan.noiseUm = xml::number(root, path, "noise-um", 0.0);
        if (!(plan.noiseUm > 0) || !std::isfinite(plan.noiseUm))
            xml::fail(root, path, "noise-um (the instrument's stated noise, one sample's standard deviation) must be a "
                                  "positive number of um");
    }
    RunCapture instrument;
    const XMLElement* instrumentElement = root.FirstChildElement("instrument");
    if (instrumentElement) {
        if (instrumentElement->NextSiblingElement("instrument"))
            xml::fail(*instrumentElement->NextSiblingElement("instrument"), path, "a plan has at most one <instrument>");
        xml::allowAttributes(*instrumentElement, path, {"angle-column", "time-column", "length-column", "pass-column",
                                                        "length-unit", "angle-unit", "time-unit", "decimal", "length", "drift"});
        readInstrument(*instrumentElement, path, instrument);
    }
    std::set<std::string> names;
    for (const auto* e = root.FirstChildElement(); e; e = e->NextSiblingElement()) {
        const std::string kind = e->Name();
        std::string name;
        if (kind == "instrument") continue;
        if (kind == "run") {
            plan.runs.push_back(readBallbarRun(*e, path, false, instrument));
            name = plan.runs.back().name;
        } else if (kind == "absolute-run") {
            plan.absoluteRuns.push_back(readBallbarRun(*e, path, true, instrument));
            name = plan.absoluteRuns.back().name;
        } else if (kind == "rtest") {
            plan.rtestRuns.push_back(readRtestRun(*e, path));
            name = plan.rtestRuns.back().name;
        } else if (kind == "dbb5") {
            plan.dbb5Runs.push_back(readDbb5Run(*e, path));
            name = plan.dbb5Runs.back().name;
        } else if (kind == "circle") {
            plan.circleRuns.push_back(readCircleRun(*e, path, instrument));
            name = plan.circleRuns.back().name;
        } else if (kind == "sphere") {
            plan.sphereRuns.push_back(readSphereRun(*e, path));
            name = plan.sphereRuns.back().name;
        } else {
            xml::fail(*e, path, fmt::format("expected <run>, <absolute-run>, <rtest>, <dbb5>, <circle> or <sphere> (or one "
                                            "<instrument>); "
                                            "did you mean <{}>?",
                                            xml::nearestName(kind, {"run", "absolute-run", "rtest", "dbb5", "circle", "sphere", "instrument"})));
        }
        if (!names.insert(name).second) xml::fail(*e, path, fmt::format("run name '{}' is used twice", name));
    }
    if (plan.runCount() == 0)
        xml::fail(root, path, "a plan needs at least one run (<run>, <absolute-run>, <rtest>, <dbb5>, <circle> or <sphere>)");
    return plan;
}

std::string formatPlanXml(const MeasurementPlan& plan) {
    std::ostringstream o;
    o << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
    o << fmt::format("<plan machine=\"{}\" description=\"{}\"{}>\n", escapeXml(plan.machine, "machine name"),
                     esc(plan.description),
                     std::isfinite(plan.noiseUm) ? fmt::format(" noise-um=\"{:g}\"", plan.noiseUm) : "");
    // One <instrument> when every ball-bar run shares its settings; runs write what differs from it.
    std::vector<const RunCapture*> captures;
    for (const auto& r : plan.runs) captures.push_back(&r.capture);
    for (const auto& r : plan.absoluteRuns) captures.push_back(&r.capture);
    for (const auto& r : plan.circleRuns) captures.push_back(&r.capture);
    RunCapture instrument;
    if (!captures.empty()) {
        const RunCapture first = instrumentPart(*captures.front());
        bool shared = true;
        for (const RunCapture* c : captures) shared = shared && instrumentPart(*c) == first;
        if (shared) instrument = first;
    }
    if (const std::string attrs = instrumentAttributes(instrument, RunCapture{}); !attrs.empty())
        o << fmt::format("  <instrument{}/>\n", attrs);
    for (const auto& r : plan.runs) formatBallbar(o, "run", r, instrument);
    for (const auto& r : plan.absoluteRuns) formatBallbar(o, "absolute-run", r, instrument);
    for (const auto& r : plan.rtestRuns) {
        o << fmt::format("  <rtest name=\"{}\" ball=\"{}\" nest-length=\"{:g}\" steps=\"{}\"", esc(r.name), vec(r.ball),
                         r.nestLength, r.steps);
        if (!r.ballOffset.isZero()) o << fmt::format(" ball-offset=\"{}\"", vec(r.ballOffset));
        if (r.estimateBall) o << " estimate-ball=\"true\"";
        o << ">\n";
        for (const RotarySweep& s : r.sweeps) {
            if (s.startDeg == s.endDeg) o << fmt::format("    <hold axis=\"{}\" deg=\"{:g}\"/>\n", esc(s.axis), s.startDeg);
            else o << fmt::format("    <sweep axis=\"{}\" start=\"{:g}\" end=\"{:g}\"/>\n", esc(s.axis), s.startDeg, s.endDeg);
        }
        o << "  </rtest>\n";
    }
    for (const auto& r : plan.dbb5Runs) {
        const bool linear = r.kind == Dbb5Run::Kind::LinearCircle, cone = r.kind == Dbb5Run::Kind::ConeFrustum;
        o << fmt::format("  <dbb5 name=\"{}\" kind=\"{}\" LB=\"{:g}\" tool-length=\"{:g}\" ball=\"{}\" start=\"{:g}\" "
                         "end=\"{:g}\" step=\"{:g}\"",
                         esc(r.name), linear ? "linear" : cone ? "cone" : "rotary", r.LB, r.toolLength, vec(r.ball),
                         r.startDeg, r.endDeg, r.stepDeg);
        if (linear) o << fmt::format(" plane=\"{}\"", esc(r.plane));
        else if (cone)
            o << fmt::format(" cone-tilt=\"{:g}\" tool-angle=\"{:g}\" bar-angle=\"{:g}\" setup=\"{:g}\"", r.coneTiltDeg,
                             r.toolAngleDeg, r.barAngleDeg, r.setupDeg);
        else o << fmt::format(" axis=\"{}\" direction=\"{}\" setup=\"{:g}\"", esc(r.axis), vec(r.barDirection), r.setupDeg);
        if (r.hold.empty()) {
            o << "/>\n";
            continue;
        }
        o << ">\n";
        for (const auto& [axis, deg] : r.hold) o << fmt::format("    <hold axis=\"{}\" deg=\"{:g}\"/>\n", esc(axis), deg);
        o << "  </dbb5>\n";
    }
    for (const auto& r : plan.circleRuns) {
        o << fmt::format("  <circle name=\"{}\" plane=\"{}\" centre=\"{}\" radius=\"{:g}\" start=\"{:g}\" arc=\"{:g}\" "
                         "step=\"{:g}\"",
                         esc(r.name), linearPlaneName(r.plane), vec(r.centre), r.radius, r.startDeg, r.arcDeg, r.stepDeg);
        if (r.toolLength != 0) o << fmt::format(" tool-length=\"{:g}\"", r.toolLength);
        if (!r.pivotOffset.isZero()) o << fmt::format(" pivot-offset=\"{}\"", vec(r.pivotOffset));
        if (r.cyclicPitch[0] != 0 || r.cyclicPitch[1] != 0)
            o << fmt::format(" pitch=\"{:g} {:g}\"", r.cyclicPitch[0], r.cyclicPitch[1]);
        for (const auto& [attr, value] : {std::pair<const char*, const std::string*>{"date", &r.date},
                                          {"instrument", &r.instrument}, {"operator", &r.operatorName}})
            if (!value->empty()) o << fmt::format(" {}=\"{}\"", attr, esc(*value));
        o << captureAttributes(r.capture, instrument);
        if (r.hold.empty()) {
            o << "/>\n";
            continue;
        }
        o << ">\n";
        for (const auto& [axis, deg] : r.hold) o << fmt::format("    <hold axis=\"{}\" deg=\"{:g}\"/>\n", esc(axis), deg);
        o << "  </circle>\n";
    }
    for (const auto& r : plan.sphereRuns) {
        o << fmt::format("  <sphere name=\"{}\" centre=\"{}\" diameter=\"{:g}\" stylus-diameter=\"{:g}\" tool-length=\"{:g}\" "
                         "approach=\"{:g}\" feed=\"{:g}\" clearance=\"{:g}\" latitude=\"{:g}\" ring=\"{}\"",
                         esc(r.name), vec(r.centre), r.diameter, r.stylusDiameter, r.toolLength, r.approach, r.feed,
                         r.clearance, r.latitudeDeg, r.ringTouches);
        if (r.window == r.window) o << fmt::format(" window=\"{:g}\"", r.window);
        if (r.triggerOffset != 0) o << fmt::format(" trigger-offset=\"{:g}\"", r.triggerOffset);
        if (!r.estimateTrigger) o << " estimate-trigger=\"false\"";
        if (!r.sphereOffset.isZero()) o << fmt::format(" sphere-offset=\"{}\"", vec(r.sphereOffset));
        if (r.triggerError != 0) o << fmt::format(" trigger-error=\"{:g}\"", r.triggerError);
        o << ">\n";
        for (const SpherePoseGroup& g : r.groups) {
            if (g.steps == 0) {
                o << "    <pose";
                for (const RotarySweep& s : g.sweeps) o << fmt::format(" {}=\"{:g}\"", esc(s.axis), s.startDeg);
                o << "/>\n";
                continue;
            }
            o << fmt::format("    <group steps=\"{}\">\n", g.steps);
            for (const RotarySweep& s : g.sweeps) {
                if (s.startDeg == s.endDeg) o << fmt::format("      <hold axis=\"{}\" deg=\"{:g}\"/>\n", esc(s.axis), s.startDeg);
                else o << fmt::format("      <sweep axis=\"{}\" start=\"{:g}\" end=\"{:g}\"/>\n", esc(s.axis), s.startDeg, s.endDeg);
            }
            o << "    </group>\n";
        }
        o << "  </sphere>\n";
    }
    o << "</plan>\n";
    return o.str();
}

void checkPlanMachine(const MeasurementPlan& plan, const std::string& planPath, const std::string& machine) {
    if (!plan.machine.empty() && plan.machine != machine)
        throw InputError(planPath, plan.line,
                         fmt::format("this plan was made for machine '{}', not for '{}' (the machine description given)",
                                     plan.machine, machine));
}

void writePlanXml(const std::string& path, const MeasurementPlan& plan) {
    const std::string text = formatPlanXml(plan);
    writeFileAtomically(path, [&](std::ostream& o) { o << text; });
}

}  // namespace cnccomp::io
