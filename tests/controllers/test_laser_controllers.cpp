// Pitch-error / leadscrew tables and backlash values of Fanuc, Sinumerik, HEIDENHAIN and ISG from ISO 230-2 laser runs
// (controllers/<name>/laser_*.hpp, `cnccomp laser --controller`). Oracles: the sample file's readings averaged by hand
// (below) with each backend's documented sign, and the ISG vendor example (Beckhoff TF5200 "Example - Non-equidistant
// bilateral SSFK": setpoint 19866.7 µm, actual 19856.5 µm (+) and 19874.7 µm (−) → −102 and 80 × 0.1 µm).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>

#include <fmt/format.h>

#include "cnccomp/io/laser_csv.hpp"
#include "cnccomp/laser_positioning.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "controllers/backend.hpp"
#include "controllers/common/laser_axis.hpp"
#include "controllers/fanuc/laser_pitch.hpp"
#include "controllers/fanuc/parameter_file.hpp"
#include "controllers/heidenhain/laser_com.hpp"
#include "controllers/heidenhain/tnc_table.hpp"
#include "controllers/isg/laser_lsec.hpp"
#include "controllers/siemens/compensation_tables.hpp"
#include "controllers/siemens/laser_eec.hpp"
#include "laser_test_machines.hpp"
#include "test_support.hpp"

namespace cnccomp {
using namespace cnccomp::io;
namespace {

const std::string kSample = test::sourcePath("samples/laser/x-axis-iso230-2.csv");

// By hand from samples/laser/x-axis-iso230-2.csv (5 runs each, µm):
//   0.0   + −1.74 −1.64 −1.92 −1.76 −2.08 → x̄↑ = −9.14/5 = −1.828;  − 2.06 1.50 1.33 1.35 1.25 → x̄↓ = 7.49/5 = 1.498
//   251.2 + 3.89 3.36 4.05 3.36 3.90 → x̄↑ = 18.56/5 = 3.712;       − 6.50 6.59 6.68 6.36 6.54 → x̄↓ = 32.67/5 = 6.534
//   500.0 + 9.21 8.06 8.56 8.47 7.82 → x̄↑ = 42.12/5 = 8.424;       − 11.51 11.69 11.65 12.06 11.37 → x̄↓ = 58.28/5 = 11.656
//   B̄ = (Σ of the 55 forward readings − Σ of the 55 reverse ones) / 55 = (195.73 − 359.31) / 55 = −2.974182
constexpr double kUp0 = -1.828, kDown0 = 1.498, kUp251 = 3.712, kDown251 = 6.534, kUp500 = 8.424, kDown500 = 11.656;
constexpr double kMeanReversal = (195.73 - 359.31) / 55;

LaserPositioningResult sample() { return evaluateLaserPositioning(readLaserCsv(kSample).runs); }

TEST(LaserControllers, OneTableControllersTakeTheReferenceDirectionAndTheMeanReversalAsBacklash) {
    const auto c = controllers::common::laserAxisCompensation(sample(), true);
    EXPECT_NEAR(c.referenceUm.front(), kUp0, 1e-9);
    EXPECT_NEAR(c.referenceUm.back(), kUp500, 1e-9);
    EXPECT_NEAR(c.backlashUm, -kMeanReversal, 1e-9);  // lost motion: positive
    const auto r = controllers::common::laserAxisCompensation(sample(), false);
    EXPECT_NEAR(r.referenceUm.back(), kDown500, 1e-9);
    // Moving + after a − approach the slide lags below the target by B̄: the motor goes −B̄ further in its direction of
    // motion, the same β (Fanuc 1851: compensation in the direction of movement).
    EXPECT_NEAR(r.backlashUm, -kMeanReversal, 1e-9);
}

// Fanuc: data = increments of the correction −(x̄↑(P) − x̄↑(0)) in 0.0001 mm from the reference position (machine 0);
// their sum up to 500 mm is the correction there to half a unit per point; 1851 = 1852 = β in detection units.
TEST(LaserControllers, FanucPitchDataSumToMinusTheErrorAndBacklashIsInDetectionUnits) {
    const controllers::fanuc::LaserPitch p = controllers::fanuc::fanucLaserPitch(sample(), 1);
    const auto f = controllers::fanuc::parseParameterFile("CNCCOMP_LASER_X.PRM", p.file);
    EXPECT_EQ(controllers::fanuc::required(f, 3620, 1), 0);
    EXPECT_EQ(controllers::fanuc::required(f, 3621, 1), 1);
    EXPECT_EQ(controllers::fanuc::required(f, 3622, 1), 10);
    EXPECT_EQ(controllers::fanuc::required(f, 3624, 1), 50);
    EXPECT_EQ(controllers::fanuc::required(f, 1851, 1), std::lround(-kMeanReversal / 0.1));  // 30
    EXPECT_EQ(controllers::fanuc::required(f, 1852, 1), 30);
    double sum = 0;
    for (int k = 1; k <= 10; ++k) sum += controllers::fanuc::required(f, 10000 + k, 0, 0);
    EXPECT_NEAR(sum * 1e-4, -(kUp500 - kUp0) * 1e-3, 0.5e-4);  // −10.252 µm, whole units: −103
    EXPECT_NEAR(p.table.correction(500.0, 1e-4), -(kUp500 - kUp0) * 1e-3, 0.5e-4);
    EXPECT_NEAR(p.table.correction(0.0, 1e-4), 0.0, 1e-12);
    EXPECT_NE(p.file.find("servo mismatch"), std::string::npos);
}

// Sinumerik: $AA_ENC_COMP = the error itself ("a positive value moves the axis negative"), MD32450 = β in mm.
TEST(LaserControllers, SiemensEecHoldsTheErrorAndBacklashTheMeanLostMotion) {
    const auto e = controllers::siemens::siemensLaserEec(sample(), "AX1");
    EXPECT_NE(e.eec.find(fmt::format("$AA_ENC_COMP[0,0,AX1]={:.6f}\n", kUp0 * 1e-3)), std::string::npos) << e.eec;
    EXPECT_NE(e.eec.find(fmt::format("$AA_ENC_COMP[0,10,AX1]={:.6f}\n", kUp500 * 1e-3)), std::string::npos) << e.eec;
    EXPECT_NE(e.eec.find("$AA_ENC_COMP_STEP[0,AX1]=50.000000\n"), std::string::npos);
    EXPECT_NE(e.machineData.find(fmt::format("$MA_BACKLASH[0,AX1]={:.6f}\n", -kMeanReversal * 1e-3)), std::string::npos)
        << e.machineData;
    EXPECT_NE(e.machineData.find("$MA_ENC_COMP_ENABLE[0,AX1]=1\n"), std::string::npos);
    EXPECT_NE(e.eec.find("POSCTRL_GAIN"), std::string::npos);
}

// HEIDENHAIN: X.COM, AXISPOS at the targets, the column of the axis' positioning component with the emit's sign
// (a gantry's X on the tool side: C1 = −error); MP710 named with β.
TEST(LaserControllers, HeidenhainComTableHoldsTheErrorAtTheTargets) {
    const auto c = controllers::heidenhain::heidenhainLaserCom(sample(), 1, -1.0);
    const auto t = controllers::heidenhain::parseTncTable(c.name, c.text, {"NR", "AXISPOS", "C1"});
    ASSERT_EQ(t.rows.size(), 11u);
    EXPECT_EQ(t.cell(5, t.column("AXISPOS")), "251.200000");
    EXPECT_NEAR(std::stod(t.cell(5, t.column("C1"))), -kUp251 * 1e-3, 1e-12);
    EXPECT_NEAR(std::stod(t.cell(0, t.column("C1"))), -kUp0 * 1e-3, 1e-12);
    EXPECT_NE(c.text.find(fmt::format("MP710 (backlash compensation, mm) of axis X to {:.6f}", -kMeanReversal * 1e-3)),
              std::string::npos) << c.text;
}

// HEIDENHAIN through the CLI agrees with `emit --controller heidenhain-tnc` (kinematics_table.cpp) on the same error:
// a deviation set whose EXX holds the laser's x̄↑ at its targets (EXX = x̄↑ / s, s = the reading per unit of EXX: +1 on
// the gantry) emits the same X.COM column at the same positions (oracle: the emit route's own convention; a sign or
// column that differed would make the two files compensate in opposite directions). The knee mill (table X moving −X
// in the bed frame) is refused by the emit route ("a TNC MachAxis X moves along +X"); its laser table is checked by
// hand: EXX = x̄↑ / (−1) on the table side, written as is: C1 = −x̄↑, the same correction as the gantry's.
TEST(LaserControllers, HeidenhainComAgreesWithTheEmitRouteOnGantryAndKneeMill) {
    const test::ScratchDir dir("laser-heidenhain");
    const std::string laserFile = test::sourcePath("samples/laser/mill-3axis-x.csv");
    const LaserPositioningResult r = evaluateLaserPositioning(readLaserCsv(laserFile).runs);
    for (const auto& [xml, s] : {std::pair{test::gantryXml(), 1.0}, std::pair{test::kneeXml(), -1.0}}) {
        const std::string machineFile = dir.file(s > 0 ? "gantry.xml" : "knee.xml");
        test::writeText(machineFile, xml);
        const std::string out = dir.file(s > 0 ? "gantry" : "knee");
        const test::CliResult cli = test::runCli(fmt::format("laser --file '{}' --controller heidenhain-tnc --machine '{}' --comp-out '{}'",
                                                             laserFile, machineFile, out));
        ASSERT_EQ(cli.exitCode, 0) << cli.out;
        const auto got = controllers::heidenhain::parseTncTable("laser X.COM", test::readText(out + "/X.COM"), {"NR", "AXISPOS", "C1"});
        EXPECT_NEAR(std::stod(got.cell(0, got.column("C1"))), -r.targets[0].meanForward * 1e-3, 1e-9);
        EXPECT_NEAR(std::stod(got.cell(8, got.column("C1"))), -r.targets[8].meanForward * 1e-3, 1e-9);
        if (s < 0) continue;
        const MachineModel m = readMachineXml(machineFile);
        DeviationSet d(m);
        const int exx = m.deviationIndex("EXX");
        for (size_t k = 0; k < r.targets.size(); ++k) d.values[m.deviations[static_cast<size_t>(exx)].offset + static_cast<int>(k)] =
                                                          r.targets[k].meanForward * 1e-3 / s;
        d.present[static_cast<size_t>(exx)] = 1;
        const controllers::EmitResult e = controllers::backend("heidenhain-tnc").emit({m, d, "laser", "2026-11-26"});
        const auto com = std::find_if(e.files.begin(), e.files.end(), [](const controllers::OutputFile& f) { return f.name == "X.COM"; });
        ASSERT_NE(com, e.files.end());
        const auto want = controllers::heidenhain::parseTncTable("emit X.COM", com->content, {"NR", "AXISPOS", "C1"});
        ASSERT_EQ(got.rows.size(), want.rows.size());
        for (size_t i = 0; i < want.rows.size(); ++i) {
            EXPECT_NEAR(std::stod(got.cell(i, got.column("AXISPOS"))), std::stod(want.cell(i, want.column("AXISPOS"))), 1e-9);
            EXPECT_NEAR(std::stod(got.cell(i, got.column("C1"))), std::stod(want.cell(i, want.column("C1"))), 1e-9) << i;
        }
    }
}

// Fanuc and Sinumerik through the CLI agree with their emit routes (fanuc-30i pitch tables, siemens-840d EEC) on the same
// error: the gantry with EXX = x̄↑ at the laser's targets; both files read back by the backends' own readers and compared
// at the targets −400, 0, 400 mm, points of both grids (oracle: the emit route's convention, see above).
TEST(LaserControllers, FanucAndSiemensAgreeWithTheirEmitRoutes) {
    const test::ScratchDir dir("laser-fanuc-siemens");
    const std::string laserFile = test::sourcePath("samples/laser/mill-3axis-x.csv");
    const LaserPositioningResult r = evaluateLaserPositioning(readLaserCsv(laserFile).runs);
    const std::string machineFile = dir.file("gantry.xml");
    test::writeText(machineFile, test::gantryXml());
    const MachineModel m = readMachineXml(machineFile);
    DeviationSet d(m);
    const int exx = m.deviationIndex("EXX");
    for (size_t k = 0; k < r.targets.size(); ++k)
        d.values[m.deviations[static_cast<size_t>(exx)].offset + static_cast<int>(k)] = r.targets[k].meanForward * 1e-3;
    d.present[static_cast<size_t>(exx)] = 1;
    const auto fileOf = [](const controllers::EmitResult& e, const std::string& name) {
        const auto it = std::find_if(e.files.begin(), e.files.end(), [&](const controllers::OutputFile& f) { return f.name == name; });
        return it == e.files.end() ? std::string() : it->content;
    };
    for (const char* controller : {"fanuc-30i", "siemens-840d"}) {
        const test::CliResult cli = test::runCli(fmt::format("laser --file '{}' --controller {} --axis-number 1 --comp-out '{}'",
                                                             laserFile, controller, dir.file(controller)));
        ASSERT_EQ(cli.exitCode, 0) << cli.out;
    }
    const controllers::EmitResult fe = controllers::backend("fanuc-30i").emit({m, d, "laser", "2026-11-26"});
    const auto fEmit = controllers::fanuc::pitchFromFile(m, controllers::fanuc::parseParameterFile("emit", fileOf(fe, "CNCCOMP.PRM")));
    const auto fLaser = controllers::fanuc::pitchFromFile(
        m, controllers::fanuc::parseParameterFile("laser", test::readText(dir.file("fanuc-30i/CNCCOMP_LASER_X.PRM"))));
    ASSERT_EQ(fEmit.size(), 1u);
    ASSERT_EQ(fLaser.size(), 1u);
    const controllers::siemens::EecTable sEmit =
        controllers::siemens::parseEec(m, "emit", fileOf(controllers::backend("siemens-840d").emit({m, d, "laser", "2026-11-26"}), "AX_EEC.INI")).at(0);
    const controllers::siemens::EecTable sLaser =
        controllers::siemens::parseEec(m, "laser", test::readText(dir.file("siemens-840d/AX_EEC.INI"))).at(0);
    for (double P : {-400.0, 0.0, 400.0}) {
        EXPECT_NEAR(fLaser[0].correction(P, 1e-4), fEmit[0].correction(P, 1e-4), 1.0e-4) << P;  // whole units, each rounded
        EXPECT_NEAR(sLaser.table.at(P), sEmit.table.at(P), 1e-6) << P;
        EXPECT_NEAR(sLaser.table.at(P), r.errorAt(P, true) * 1e-3, 1e-6) << P;
    }
}

// ISG: bilateral: .pos = x̄↑, .neg = x̄↓ in 0.1 µm at the targets (0.1 µm setpoints); the vendor's own example row.
TEST(LaserControllers, IsgBilateralListFollowsTheVendorExample) {
    const std::string s = controllers::isg::isgLaserLsec(sample(), 1, "X");
    EXPECT_NE(s.find("kw.ssfk.bilateral                   1\n"), std::string::npos);
    EXPECT_NE(s.find("kw.ssfk.table[5].setpoint 2512000\n"), std::string::npos) << s;
    EXPECT_NE(s.find(fmt::format("kw.ssfk.table[5].pos {}\n", std::lround(kUp251 * 10))), std::string::npos) << s;     // 37
    EXPECT_NE(s.find(fmt::format("kw.ssfk.table[5].neg {}\n", std::lround(kDown251 * 10))), std::string::npos) << s;   // 65
    EXPECT_NE(s.find(fmt::format("kw.ssfk.table[0].neg {}\n", std::lround(kDown0 * 10))), std::string::npos) << s;     // 15

    // The vendor example: at setpoint 19866.7 µm the axis reached 19856.5 µm in + and 19874.7 µm in −.
    LaserPositioningRuns in;
    in.axis = "Y";
    in.targets = {0.0, 10.0, 19.8667, 30.0, 40.0};
    for (int j = 0; j < 5; ++j) {
        in.forward.push_back({0, 0, 19856.5 - 19866.7, 0, 0});
        in.reverse.push_back({0, 0, 19874.7 - 19866.7, 0, 0});
    }
    const std::string v = controllers::isg::isgLaserLsec(evaluateLaserPositioning(in), 2, "Y AXIS");
    EXPECT_NE(v.find("kw.ssfk.table[2].setpoint 198667\n"), std::string::npos) << v;
    EXPECT_NE(v.find("kw.ssfk.table[2].pos -102\n"), std::string::npos) << v;
    EXPECT_NE(v.find("kw.ssfk.table[2].neg 80\n"), std::string::npos) << v;
    EXPECT_NE(v.find("kopf.achs_nr                        2\n"), std::string::npos) << v;
}

// Through the executable: each controller's files are written; a missing axis number is refused (exit 2, nothing written).
TEST(LaserControllers, CliWritesEachControllersFilesAndRefusesAMissingAxisNumber) {
    const test::ScratchDir dir("laser-controllers");
    for (const auto& [controller, file] : {std::pair{"fanuc-30i", "CNCCOMP_LASER_X.PRM"}, std::pair{"siemens-840d", "AX_EEC.INI"},
                                           std::pair{"isg", "LSEC_X.LIS"}}) {
        const std::string out = dir.file(controller);
        const test::CliResult r = test::runCli(fmt::format("laser --file '{}' --controller {} --axis-number 1 --comp-out '{}'",
                                                           kSample, controller, out));
        EXPECT_EQ(r.exitCode, 0) << r.out;
        EXPECT_TRUE(std::filesystem::exists(out + "/" + file)) << controller;
    }
    const test::CliResult bad = test::runCli(fmt::format("laser --file '{}' --controller fanuc-30i --comp-out '{}'", kSample,
                                                         dir.file("none")));
    EXPECT_EQ(bad.exitCode, 2) << bad.out;
    EXPECT_NE(bad.out.find("needs --axis-number"), std::string::npos) << bad.out;
    EXPECT_FALSE(std::filesystem::exists(dir.file("none")));
}

}  // namespace
}  // namespace cnccomp
