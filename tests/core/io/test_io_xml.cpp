// Machine and plan XML: unknown elements and attributes are errors naming the line and the nearest known name
// (`<instrument lenght-unit="mm">` was ignored and every trace read 1000x too small); X, Y, Z parallel.
#include <gtest/gtest.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "test_support.hpp"

namespace cnccomp {
using namespace cnccomp::io;
namespace {

template <typename F>
std::string inputErrorOf(F&& f) {
    try {
        f();
    } catch (const InputError& e) {
        return e.what();
    }
    return "(no InputError)";
}

void expectHas(const std::string& message, std::initializer_list<const char*> parts) {
    for (const char* p : parts) EXPECT_NE(message.find(p), std::string::npos) << message << "  lacks: " << p;
}

TEST(PlanXmlStrict, MisspeltAttributeNamesTheLineAndTheNearestName) {
    test::ScratchDir dir("io-xml-plan");
    const std::string p = dir.file("plan.xml");
    test::writeText(p, "<plan machine=\"multitasking\">\n  <instrument lenght-unit=\"mm\"/>\n"
                       "  <run name=\"B-X\" test=\"B-X\" LB=\"100\" RB=\"360\" RC=\"50\" ZC=\"300\"/>\n</plan>\n");
    expectHas(inputErrorOf([&] { readPlanXml(p); }), {"plan.xml:2", "lenght-unit", "did you mean 'length-unit'"});
    test::writeText(p, "<plan machine=\"multitasking\">\n"
                       "  <run name=\"B-X\" test=\"B-X\" LB=\"100\" RB=\"360\" RC=\"50\" ZC=\"300\" stpe=\"2\"/>\n</plan>\n");
    expectHas(inputErrorOf([&] { readPlanXml(p); }), {"plan.xml:2", "stpe", "'step'"});
    test::writeText(p, "<plan machine=\"multitasking\">\n  <rnu name=\"B-X\" test=\"B-X\" LB=\"100\" RB=\"360\" ZC=\"300\"/>\n</plan>\n");
    expectHas(inputErrorOf([&] { readPlanXml(p); }), {"plan.xml:2", "<rnu>", "<run>"});
    test::writeText(p, "<plan machine=\"multitasking\" descripton=\"x\">\n"
                       "  <run name=\"B-X\" test=\"B-X\" LB=\"100\" RB=\"360\" RC=\"50\" ZC=\"300\"/>\n</plan>\n");
    expectHas(inputErrorOf([&] { readPlanXml(p); }), {"plan.xml:1", "'description'"});
    // Every sample plan still reads.
    for (const char* s : {"dbb5-table-table-ac", "dbb5-table-table-bc", "lsq-multitasking-b-runs", "lsq-multitasking-mounting",
                          "lsq-multitasking-planned", "multitasking-six-circles-recorded", "multitasking-six-circles",
                          "table-table-ac-kinematic", "table-table-ac-rtest", "tilting-head-b-patterns"})
        EXPECT_NO_THROW(readPlanXml(test::sourcePath(std::string("samples/plans/") + s + ".xml"))) << s;
}

TEST(MachineXmlStrict, UnknownElementsAndAttributesAreNamed) {
    test::ScratchDir dir("io-xml-machine");
    const std::string p = dir.file("m.xml");
    const std::string axes = "<axis name=\"X\" type=\"linear\" direction=\"1 0 0\"/>\n"
                             "<axis name=\"Y\" type=\"linear\" direction=\"0 1 0\"/>\n";
    test::writeText(p, "<machine name=\"m\">\n<tool>\n" + axes + "<axis name=\"Z\" type=\"linear\" direction=\"0 0 1\" mni=\"0\"/>\n</tool>\n</machine>\n");
    expectHas(inputErrorOf([&] { readMachineXml(p); }), {"m.xml:5", "mni", "'min'"});
    test::writeText(p, "<machine name=\"m\">\n<tool>\n" + axes + "</tool>\n<deviation>\n</deviation>\n</machine>\n");
    expectHas(inputErrorOf([&] { readMachineXml(p); }), {"m.xml:6", "<deviation>", "<deviations>"});
    test::writeText(p, "<machine name=\"m\">\n<tool>\n" + axes + "</tool>\n<deviations>\n"
                       "<location name=\"EX0Y\" link=\"Y\" component=\"x\" alais=\"dx\"/>\n</deviations>\n</machine>\n");
    expectHas(inputErrorOf([&] { readMachineXml(p); }), {"m.xml:7", "alais", "'alias'"});
    test::writeText(p, "<machine name=\"m\">\n<tool>\n" + axes + "<axs name=\"Z\" type=\"linear\" direction=\"0 0 1\"/>\n</tool>\n</machine>\n");
    expectHas(inputErrorOf([&] { readMachineXml(p); }), {"m.xml:5", "<axs>", "<axis>"});
    for (const char* s : {"controllers-fanuc-pitch", "controllers-heidenhain-components", "controllers-siemens-components",
                          "controllers-table-table-ac", "controllers-tilting-head-b", "multitasking", "table-table-ac",
                          "table-table-bc-offsets", "table-table-bc", "tilting-head-b"})
        EXPECT_NO_THROW(readMachineXml(test::sourcePath(std::string("samples/machines/") + s + ".xml"))) << s;
}

// Oracle: ISO 841 (X, Y, Z at right angles). A Y axis typed with X's direction, or turned onto X by its placement,
// is refused at its line; a W axis parallel to Z (a secondary axis) is not.
TEST(MachineXmlStrict, ParallelPrimaryAxesAreRefused) {
    test::ScratchDir dir("io-xml-parallel");
    const std::string p = dir.file("m.xml");
    test::writeText(p, "<machine name=\"m\">\n<tool>\n<axis name=\"X\" type=\"linear\" direction=\"1 0 0\"/>\n"
                       "<axis name=\"Y\" type=\"linear\" direction=\"1 0 0\"/>\n"
                       "<axis name=\"Z\" type=\"linear\" direction=\"0 0 1\"/>\n</tool>\n</machine>\n");
    expectHas(inputErrorOf([&] { readMachineXml(p); }), {"m.xml:4", "X and Y are parallel"});
    test::writeText(p, "<machine name=\"m\">\n<workpiece>\n<axis name=\"Y\" type=\"linear\" direction=\"0 1 0\" "
                       "rotation=\"0 0 -90\"/>\n</workpiece>\n<tool>\n<axis name=\"X\" type=\"linear\" direction=\"1 0 0\"/>\n"
                       "<axis name=\"Z\" type=\"linear\" direction=\"0 0 1\"/>\n</tool>\n</machine>\n");
    expectHas(inputErrorOf([&] { readMachineXml(p); }), {"m.xml:", "parallel"});
    test::writeText(p, "<machine name=\"m\">\n<workpiece>\n<axis name=\"W\" type=\"linear\" direction=\"0 0 1\"/>\n</workpiece>\n"
                       "<tool>\n<axis name=\"X\" type=\"linear\" direction=\"1 0 0\"/>\n<axis name=\"Y\" type=\"linear\" "
                       "direction=\"0 1 0\"/>\n<axis name=\"Z\" type=\"linear\" direction=\"0 0 1\"/>\n</tool>\n</machine>\n");
    EXPECT_NO_THROW(readMachineXml(p));
}

}  // namespace
}  // namespace cnccomp
