// The deviation set's reversal values written by `emit` where each controller holds backlash (controllers/common/
// set_backlash.hpp): Fanuc 1851/1852 (detection units), Sinumerik MD32450 $MA_BACKLASH (mm), HEIDENHAIN MP710 (mm), ISG
// getriebe[0].lose (0.1 um) with lr_param.anwahl_losekomp 1. Oracles: the vendors' texts as cited in set_backlash.hpp
// (β = −B̄, positive for the usual lost motion; units as each manual gives them), the values written out by hand here;
// and each backend's own reader (apply) giving back the drive offset the vendors describe (−β while moving against the
// reference approach, 0 with it).
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <string>

#include <fmt/format.h>

#include "cnccomp/io/machine_xml.hpp"
#include "controllers/backend.hpp"
#include "controllers/common/directional.hpp"
#include "controllers/fanuc/parameter_file.hpp"
#include "laser_test_machines.hpp"
#include "test_support.hpp"

namespace cnccomp {
using namespace cnccomp::io;
namespace {

std::string fileOf(const controllers::EmitResult& e, const std::string& name) {
    const auto it = std::find_if(e.files.begin(), e.files.end(), [&](const controllers::OutputFile& f) { return f.name == name; });
    return it == e.files.end() ? std::string("<missing " + name + ">") : it->content;
}

bool listed(const std::vector<controllers::Coverage>& list, const std::string& name) {
    return std::any_of(list.begin(), list.end(), [&](const controllers::Coverage& c) { return c.deviation == name; });
}

// BX = −3.0 µm (lost motion: β = +3.0 µm), BY = +1.2 µm (the slide overshoots: β = −1.2 µm), no BZ.
TEST(SetBacklash, EmitWritesValueSignAndUnitForEveryController) {
    const test::ScratchDir dir("set-backlash");
    test::writeText(dir.file("gantry.xml"), test::gantryXml());
    const MachineModel m = readMachineXml(dir.file("gantry.xml"));
    DeviationSet d(m);
    d.set("EC0Y", 2.0 * kArcsec);
    d.setReversal("X", -3.0 * kUm);
    d.setReversal("Y", 1.2 * kUm);
    struct Case {
        const char* controller;
        const char* file;
        std::vector<std::string> lines;  // written by hand from the manuals' units and β = −B̄
    };
    const std::vector<Case> cases{
        // Fanuc: detection unit 0.0001 mm (IS-C): 3.0 µm = 30, −1.2 µm = −12; axis-type lines N<nr>Q1A<axis>P<value>.
        {"fanuc-30i", "CNCCOMP.PRM", {"N01851Q1A1P30A2P-12", "N01852Q1A1P30A2P-12"}},
        // Sinumerik MD32450 in mm, first measuring system.
        {"siemens-840d", "CNCCOMP_BACKLASH.INI", {"$MA_BACKLASH[0,AX1]=0.003000", "$MA_BACKLASH[0,AX2]=-0.001200"}},
        // HEIDENHAIN MP710 in mm, X = .0, Y = .1.
        {"heidenhain-tnc", "CNCCOMP_BACKLASH.MP", {"MP710.0:+0.003000", "MP710.1:-0.001200"}},
        // ISG P-AXIS-00103 in 0.1 µm, one axis list each.
        {"isg", "backlash_X.lis", {"lr_param.anwahl_losekomp            1", "getriebe[0].lose                    30"}},
        {"isg", "backlash_Y.lis", {"lr_param.anwahl_losekomp            1", "getriebe[0].lose                    -12"}},
    };
    for (const Case& c : cases) {
        const controllers::EmitResult e = controllers::backend(c.controller).emit({m, d, "set.csv", "2026-11-26"});
        const std::string text = fileOf(e, c.file);
        for (const std::string& l : c.lines) EXPECT_NE(text.find(l + "\n"), std::string::npos) << c.controller << ": " << l << "\n" << text;
        EXPECT_TRUE(listed(e.compensated, "BX")) << c.controller;
        EXPECT_TRUE(listed(e.compensated, "BY")) << c.controller;
        EXPECT_FALSE(listed(e.notCompensated, "BX")) << c.controller;
        EXPECT_FALSE(listed(e.compensated, "BZ")) << c.controller;
        // No Z backlash anywhere.
        EXPECT_EQ(fileOf(e, "backlash_Z.lis").rfind("<missing", 0), 0u) << c.controller;
        EXPECT_EQ(text.find("AX3]="), std::string::npos) << c.controller;
        EXPECT_EQ(text.find("MP710.2"), std::string::npos) << c.controller;

        // Read back by the backend: moving −X the drive goes β = 3 µm further −, moving +X not at all; −Y: +1.2 µm.
        const std::unique_ptr<controllers::AppliedCompensation> a = controllers::backend(c.controller).apply(m, e.files);
        AxisVector q(3), plus(3), minus(3);
        q << 10, 20, -100;
        plus << 1, 1, 1;
        minus << -1, -1, -1;
        const AxisVector still = a->driveCommandsForTool(q, 0.0);
        const auto* dir = dynamic_cast<const controllers::common::DirectionalCompensation*>(a.get());
        ASSERT_NE(dir, nullptr) << c.controller;
        const AxisVector up = dir->driveCommandsMoving(q, 0.0, plus), down = dir->driveCommandsMoving(q, 0.0, minus);
        EXPECT_NEAR(up[0] - still[0], 0.0, 1e-12) << c.controller;
        EXPECT_NEAR(down[0] - still[0], -0.003, 1e-9) << c.controller;
        EXPECT_NEAR(down[1] - still[1], 0.0012, 1e-9) << c.controller;
        EXPECT_NEAR(down[2] - still[2], 0.0, 1e-12) << c.controller;
    }
}

// A set without reversal values writes no backlash file and no backlash parameter (the files as before).
TEST(SetBacklash, NoReversalNoBacklash) {
    const test::ScratchDir dir("set-backlash-none");
    test::writeText(dir.file("gantry.xml"), test::gantryXml());
    const MachineModel m = readMachineXml(dir.file("gantry.xml"));
    DeviationSet d(m);
    d.set("EC0Y", 2.0 * kArcsec);
    for (const char* c : {"fanuc-30i", "siemens-840d", "heidenhain-tnc", "isg"}) {
        const controllers::EmitResult e = controllers::backend(c).emit({m, d, "set.csv", "2026-11-26"});
        for (const controllers::OutputFile& f : e.files) {
            EXPECT_EQ(f.name.find("BACKLASH"), std::string::npos) << c << " " << f.name;
            EXPECT_EQ(f.name.find("backlash"), std::string::npos) << c << " " << f.name;
            EXPECT_EQ(f.content.find("N01851"), std::string::npos) << c << " " << f.name;
        }
    }
}

}  // namespace
}  // namespace cnccomp
