#include "cnccomp/io/plan_xml.hpp"

#include <ostream>
#include <set>
#include <sstream>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/text_util.hpp"
#include "cnccomp/io/xml_util.hpp"

namespace cnccomp {

MeasurementPlan readPlanXml(const std::string& path) {
    tinyxml2::XMLDocument doc;
    xml::load(doc, path);
    const auto& root = xml::root(doc, path, "plan");
    MeasurementPlan plan;
    plan.machine = xml::textOr(root, "machine", "");
    plan.description = xml::textOr(root, "description", "");
    std::set<std::string> names;
    for (const auto* e = root.FirstChildElement(); e; e = e->NextSiblingElement()) {
        if (std::string(e->Name()) != "run") xml::fail(*e, path, "expected <run>");
        BallbarRun r;
        r.name = xml::text(*e, path, "name");
        if (!names.insert(r.name).second) xml::fail(*e, path, fmt::format("run name '{}' is used twice", r.name));
        const std::string test = xml::text(*e, path, "test");
        const auto t = parseTest(test);
        if (!t)
            xml::fail(*e, path, fmt::format("unknown test '{}'; expected one of B-X B-Y B-Z C-radial C-tangential "
                                            "C-axial C-X C-Y C-Z B-radial B-tangential B-axial",
                                            test));
        r.test = *t;
        r.LB = xml::number(*e, path, "LB");
        r.RB = xml::number(*e, path, "RB");
        r.RC = xml::number(*e, path, "RC", 0.0);
        r.ZC = xml::number(*e, path, "ZC");
        r.startDeg = xml::number(*e, path, "start", 0.0);
        r.endDeg = xml::number(*e, path, "end", 360.0);
        r.stepDeg = xml::number(*e, path, "step", 1.0);
        r.toolBallOffset = xml::vec3(*e, path, "tool-ball-offset", Vec3::Zero());
        r.workBallOffset = xml::vec3(*e, path, "work-ball-offset", Vec3::Zero());
        const std::string est = xml::textOr(*e, "estimate-mounting", "none");
        if (est != "none" && est != "tool" && est != "work" && est != "both")
            xml::fail(*e, path, fmt::format("estimate-mounting '{}' is not none, tool, work or both", est));
        r.estimateToolBallOffset = est == "tool" || est == "both";
        r.estimateWorkBallOffset = est == "work" || est == "both";
        r.headAxis = xml::textOr(*e, "head-axis", "B");
        r.tableAxis = xml::textOr(*e, "table-axis", "C");
        try {
            r.validate();
        } catch (const ModelError& ex) {
            xml::fail(*e, path, ex.what());
        }
        plan.runs.push_back(std::move(r));
    }
    if (plan.runs.empty()) xml::fail(root, path, "a plan needs at least one <run>");
    return plan;
}

std::string formatPlanXml(const MeasurementPlan& plan) {
    std::ostringstream o;
    o << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
    o << fmt::format("<plan machine=\"{}\" description=\"{}\">\n", plan.machine, plan.description);
    for (const auto& r : plan.runs) {
        o << fmt::format("  <run name=\"{}\" test=\"{}\" LB=\"{:g}\" RB=\"{:g}\" RC=\"{:g}\" ZC=\"{:g}\" start=\"{:g}\" "
                         "end=\"{:g}\" step=\"{:g}\"",
                         r.name, testName(r.test), r.LB, r.RB, r.RC, r.ZC, r.startDeg, r.endDeg, r.stepDeg);
        if (!r.toolBallOffset.isZero())
            o << fmt::format(" tool-ball-offset=\"{:g} {:g} {:g}\"", r.toolBallOffset.x(), r.toolBallOffset.y(), r.toolBallOffset.z());
        if (!r.workBallOffset.isZero())
            o << fmt::format(" work-ball-offset=\"{:g} {:g} {:g}\"", r.workBallOffset.x(), r.workBallOffset.y(), r.workBallOffset.z());
        if (r.estimateToolBallOffset || r.estimateWorkBallOffset)
            o << fmt::format(" estimate-mounting=\"{}\"", r.estimateToolBallOffset && r.estimateWorkBallOffset ? "both"
                                                           : r.estimateToolBallOffset                             ? "tool"
                                                                                                                  : "work");
        if (r.headAxis != "B") o << fmt::format(" head-axis=\"{}\"", r.headAxis);
        if (r.tableAxis != "C") o << fmt::format(" table-axis=\"{}\"", r.tableAxis);
        o << "/>\n";
    }
    o << "</plan>\n";
    return o.str();
}

void writePlanXml(const std::string& path, const MeasurementPlan& plan) {
    const std::string text = formatPlanXml(plan);
    writeFileAtomically(path, [&](std::ostream& o) { o << text; });
}

}  // namespace cnccomp
