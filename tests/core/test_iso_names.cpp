// ISO 230-1 names mean what the standard defines; paper aliases keep their own signs (iso_names.hpp, README
// "Deviation names and signs").
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>
#include <random>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "cnccomp/iso_names.hpp"
#include "cnccomp/kinematics.hpp"
#include "controllers/backend.hpp"
#include "test_support.hpp"

namespace cnccomp {
using namespace cnccomp::io;
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

MachineModel sample(const std::string& name) { return readMachineXml(test::sourcePath("samples/machines/" + name + ".xml")); }

/// Every location error at a random link value (±20 um, ±30 arcsec), all present.
DeviationSet randomLinks(const MachineModel& m, unsigned seed) {
    DeviationSet d(m);
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-1, 1);
    for (size_t i = 0; i < m.deviations.size(); ++i) {
        const DeviationDef& def = m.deviations[i];
        if (def.kind != DeviationKind::Location) continue;
        d.values[def.offset] = def.isAngle() ? u(rng) * 30 * kArcsec : u(rng) * 0.02;
        d.present[i] = 1;
    }
    return d;
}

// ---- Oracle: the ISO 230-1 definitions transcribed from the standard's wording (README table), evaluated on the exact
// kinematics with no use of iso_names: directions of the axes at zero commands (Kinematics::jointFrames), the
// reference frame x along the X motion, y in the plane of X and Y, z = x × y.
struct Geometry {
    Vec3 x, y, z;                  ///< reference frame
    std::map<std::string, JointFrame> axis;
    Vec3 toolDirection;            ///< spindle → tip at zero commands, bed frame
};

Geometry geometry(const MachineModel& m, const DeviationSet& d) {
    const Kinematics k(m, d);
    const AxisVector q = AxisVector::Zero(m.axisCount());
    Geometry g;
    const JointFrames actual = k.jointFrames(q), nominal = Kinematics(m).jointFrames(q);  // same order
    for (int i = 0; i < actual.count; ++i) {
        JointFrame f = actual.items[static_cast<size_t>(i)];
        if (f.direction.dot(nominal.items[static_cast<size_t>(i)].direction) < 0) f.direction = -f.direction;
        g.axis[m.axisNames[static_cast<size_t>(f.axis)]] = f;
    }
    g.x = g.axis.at("X").direction.normalized();
    g.y = (g.axis.at("Y").direction - g.axis.at("Y").direction.dot(g.x) * g.x).normalized();
    g.z = g.x.cross(g.y);
    g.toolDirection = k.baseToTool(q).linear() * m.toolDirection;
    return g;
}

Vec3 inReference(const Geometry& g, const Vec3& v) { return {v.dot(g.x), v.dot(g.y), v.dot(g.z)}; }

/// The ISO value of `name` from the geometry, for the names the oracle knows (squareness; position and orientation
/// of an axis carried by the bed or the slides; zero position of a tilting head from its spindle). NaN otherwise.
double isoFromGeometry(const MachineModel& m, const Geometry& g, const std::string& name) {
    const auto angle = [](const Vec3& a, const Vec3& b) { return std::acos(a.normalized().dot(b.normalized())); };
    const Vec3 X = g.axis.at("X").direction, Y = g.axis.at("Y").direction, Z = g.axis.at("Z").direction;
    if (name == "EC0Y") return angle(X, Y) - kPi / 2;  // X∠Y = 90° + EC0Y
    if (name == "EB0Z") return kPi / 2 - angle(Z, X);  // Z∠X = 90° − EB0Z
    if (name == "EA0Z") return angle(Y, Z) - kPi / 2;  // Y∠Z = 90° + EA0Z
    if (name.size() != 4 || name[2] != '0') return kNaN;
    const std::string ax(1, name[3]);
    const auto it = g.axis.find(ax);
    if (it == g.axis.end() || !it->second.rotary) return kNaN;
    // Carried by another rotary axis: not this oracle's business.
    const Side side = it->second.side;
    for (const Link& l : m.chain(side).links) {
        if (l.name == ax) break;
        if (l.kind == AxisKind::Rotary) return kNaN;
    }
    const Vec3 u = inReference(g, it->second.direction), p = inReference(g, it->second.point);
    const char e = name[1];
    if (ax == "C") {  // nominal +Z: rotation about X tilts it towards −Y, about Y towards +X
        if (e == 'A') return std::atan2(-u.y(), u.z());
        if (e == 'B') return std::atan2(u.x(), u.z());
        const double s = -p.z() / u.z();  // where the line crosses z = 0
        if (e == 'X') return p.x() + s * u.x();
        if (e == 'Y') return p.y() + s * u.y();
    }
    if (ax == "A") {  // nominal +X
        if (e == 'B') return std::atan2(-u.z(), u.x());
        if (e == 'C') return std::atan2(u.y(), u.x());
        const double s = -p.x() / u.x();
        if (e == 'Y') return p.y() + s * u.y();
        if (e == 'Z') return p.z() + s * u.z();
    }
    if (ax == "B") {  // nominal +Y
        if (e == 'A') return std::atan2(u.z(), u.y());
        if (e == 'C') return std::atan2(-u.x(), u.y());
        if (e == 'B') {  // zero position: the head's spindle (nominal −Z at B = 0) turned about +Y
            const Vec3 t = inReference(g, g.toolDirection);
            return std::atan2(-t.x(), -t.z());
        }
        const double s = -p.y() / u.y();
        if (e == 'X') return p.x() + s * u.x();
        if (e == 'Z') return p.z() + s * u.z();
    }
    return kNaN;
}

TEST(IsoNames, EveryIsoNameOfTheSampleMachinesMeasuresWhatTheStandardDefines) {
    // Oracle: the ISO definitions on the exact geometry (above), not iso_names. First order: the tolerance allows the
    // second-order terms of 30" errors (1e-3 relative) plus rounding.
    int checked = 0;
    for (const char* file : {"multitasking", "table-table-ac", "tilting-head-b", "controllers-siemens-components",
                             "controllers-heidenhain-components", "controllers-fanuc-pitch", "controllers-table-table-ac",
                             "controllers-tilting-head-b"}) {
        const MachineModel m = sample(file);
        for (unsigned seed : {1u, 2u, 3u}) {
            DeviationSet d = randomLinks(m, seed);
            // The tilting-head zero position is read from the spindle: keep the spindle's own tilt out of it.
            for (const char* s : {"EA0S", "EB0S"})
                if (m.deviationIndex(s) >= 0) d.setLinkValue(s, 0.0);
            const Geometry g = geometry(m, d);
            for (size_t i = 0; i < m.deviations.size(); ++i) {
                const DeviationDef& def = m.deviations[i];
                if (def.kind != DeviationKind::Location) continue;
                const double want = isoFromGeometry(m, g, def.name);
                if (std::isnan(want)) continue;
                const double tol = def.isAngle() ? 2e-3 * std::abs(want) + 0.01 * kArcsec : 2e-3 * std::abs(want) + 1e-6;
                EXPECT_NEAR(d.get(def.name), want, tol) << file << " " << def.name << " = " << isoMeaningText(m, static_cast<int>(i));
                ++checked;
            }
        }
    }
    EXPECT_GE(checked, 3 * 40);
}

TEST(IsoNames, SampleMachinesHaveTheRelationsOfTheReadmeTable) {
    // Oracle: the README table, derived by hand from the ISO definitions (independent of the code's derivation).
    const MachineModel mt = sample("multitasking");
    EXPECT_EQ(isoMeaningText(mt, mt.deviationIndex("EC0Y")), "EC0Y = -gXY");
    EXPECT_EQ(isoMeaningText(mt, mt.deviationIndex("EA0Z")), "EA0Z = -aYZ");
    EXPECT_EQ(isoMeaningText(mt, mt.deviationIndex("EB0Z")), "EB0Z = -bYZ");
    EXPECT_EQ(isoMeaningText(mt, mt.deviationIndex("EA0C")), "EA0C = -aYZ + aCZ");
    EXPECT_EQ(isoMeaningText(mt, mt.deviationIndex("EB0C")), "EB0C = -bYZ + bCZ");
    for (const char* same : {"EX0C1", "EZ0C1", "EA0C1", "EA0B", "EB0B", "EC0B", "EX0C", "EY0C"})
        EXPECT_EQ(mt.deviations[static_cast<size_t>(mt.deviationIndex(same))].isoTerms.size(), 1u) << same;
    const MachineModel tt = sample("table-table-ac");
    EXPECT_EQ(isoMeaningText(tt, tt.deviationIndex("EC0Y")), "EC0Y = -CXY");
    EXPECT_EQ(isoMeaningText(tt, tt.deviationIndex("EC0A")), "EC0A = [A.c] - CXY");
    EXPECT_EQ(isoMeaningText(tt, tt.deviationIndex("EA0Z")), "EA0Z = [Z.a]");
    EXPECT_EQ(tt.deviations[static_cast<size_t>(tt.deviationIndex("EA0Z"))].aliasSign, -1.0);  // CYZ = 90° − Y∠Z
    const MachineModel th = sample("tilting-head-b");
    EXPECT_EQ(isoMeaningText(th, th.deviationIndex("EC0Y")), "EC0Y = [Y.c]");
    EXPECT_EQ(isoMeaningText(th, th.deviationIndex("EC0B")), "EC0B = [Y.c] + exB");
    EXPECT_EQ(isoMeaningText(th, th.deviationIndex("EA0B")), "EA0B = [Z.a] + eBz");
    EXPECT_EQ(isoMeaningText(th, th.deviationIndex("EB0B")), "EB0B = [Z.b] + [B.b]");
}

TEST(IsoNames, TheSameGeometryReadsUnderEitherName) {
    // Hand-computed: multitasking-truth's paper values gXY = 3", aYZ = 5", bYZ = −6", aCZ = 8", bCZ = −5.5" are, in
    // ISO terms, EC0Y = −3", EA0Z = −5", EB0Z = 6", EA0C = 8 − 5 = 3", EB0C = −5.5 + 6 = 0.5".
    const MachineModel& m = test::multitasking();
    test::ScratchDir dir("iso-names");
    test::writeText(dir.file("iso.csv"), "# cnccomp-deviations/2\nname,value,unit\nEC0Y,-3,arcsec\nEA0Z,-5,arcsec\nEB0Z,6,arcsec\nEA0C,3,arcsec\n"
                                         "EB0C,0.5,arcsec\nEX0C,-15,um\n");
    test::writeText(dir.file("paper.csv"), "alias,value,unit\ngXY,3,arcsec\naYZ,5,arcsec\nbYZ,-6,arcsec\naCZ,8,arcsec\n"
                                           "bCZ,-5.5,arcsec\ndxCZ,-15,um\n");
    const DeviationSet a = readDeviationCsv(dir.file("iso.csv"), m), b = readDeviationCsv(dir.file("paper.csv"), m);
    EXPECT_LT((a.values - b.values).cwiseAbs().maxCoeff(), 1e-15);
    EXPECT_NEAR(a.linkValue("aCZ"), 8 * kArcsec, 1e-15);
    EXPECT_NEAR(b.get("EA0C"), 3 * kArcsec, 1e-15);
    EXPECT_NEAR(b.get("EC0Y"), -3 * kArcsec, 1e-15);
    EXPECT_NEAR(a.get("gXY"), 3 * kArcsec, 1e-15);
    EXPECT_EQ(a.present, b.present);
    // Absent deviations are zero under their ISO names in an ISO file: EA0C absent with EA0Z given means C is square
    // to Y (aCZ = aYZ), and zero under the alias in a paper file (aCZ = 0).
    test::writeText(dir.file("iso2.csv"), "# cnccomp-deviations/2\nname,value,unit\nEA0Z,-5,arcsec\n");
    test::writeText(dir.file("paper2.csv"), "name,value,unit\naYZ,5,arcsec\n");
    EXPECT_NEAR(readDeviationCsv(dir.file("iso2.csv"), m).get("EA0C"), 0.0, 1e-18);
    EXPECT_NEAR(readDeviationCsv(dir.file("paper2.csv"), m).get("aCZ"), 0.0, 1e-18);
    // A negative alias sign: CYZ = −EA0Z on the table-table machine (90° minus the angle Y∠Z).
    const MachineModel tt = sample("table-table-ac");
    test::writeText(dir.file("tt-iso.csv"), "# cnccomp-deviations/2\nname,value,unit\nEA0Z,35,um/m\nEC0Y,2,um/m\nEC0A,149,um/m\n");
    test::writeText(dir.file("tt-paper.csv"), "# cnccomp-deviations/2\nname,value,unit\nCYZ,-35,um/m\nCXY,-2,um/m\nEC0A,149,um/m\n");
    const DeviationSet c = readDeviationCsv(dir.file("tt-iso.csv"), tt), e = readDeviationCsv(dir.file("tt-paper.csv"), tt);
    EXPECT_LT((c.values - e.values).cwiseAbs().maxCoeff(), 1e-16);
    EXPECT_NEAR(c.linkValue("EC0A"), 147e-6, 1e-15);  // EC0A = [A.c] − CXY
}

TEST(IsoNames, AFileWrittenAndReadBackKeepsItsMeaning) {
    // Round trip through our own writer and reader on every sample machine (the same code both ways: it shows the
    // two agree; the oracle tests above show what the numbers mean).
    for (const char* file : {"multitasking", "table-table-ac", "tilting-head-b", "controllers-siemens-components",
                             "controllers-heidenhain-components"}) {
        const MachineModel m = sample(file);
        const DeviationSet d = randomLinks(m, 7);
        test::ScratchDir dir("iso-roundtrip");
        writeDeviationCsv(dir.file("d.csv"), d);
        const DeviationSet back = readDeviationCsv(dir.file("d.csv"), m);
        EXPECT_LT((back.values - d.values).cwiseAbs().maxCoeff(), 2e-6 * kUm) << file;  // 6 decimals in um / arcsec
        EXPECT_EQ(back.present, d.present) << file;
        // Every row's value is the ISO value, alias_value the paper's.
        const std::string text = formatDeviationCsv(d);
        if (std::string(file) == "multitasking") {
            EXPECT_NE(text.find(fmt::format("EC0Y,gXY,{:.6f},arcsec,{:.6f}\n", d.get("EC0Y") / kArcsec, d.get("gXY") / kArcsec)),
                      std::string::npos)
                << text;
            EXPECT_NEAR(d.get("EC0Y"), -d.get("gXY"), 1e-18);
        }
    }
}

TEST(IsoNames, AmbiguousOrInconsistentRowsAreRefusedWithTheirLine) {
    const MachineModel& m = test::multitasking();
    test::ScratchDir dir("iso-bad");
    const auto expectError = [&](const std::string& body, std::initializer_list<const char*> parts) {
        test::writeText(dir.file("d.csv"), body);
        try {
            readDeviationCsv(dir.file("d.csv"), m);
            ADD_FAILURE() << "accepted: " << body;
        } catch (const InputError& e) {
            for (const char* p : parts) EXPECT_NE(std::string(e.what()).find(p), std::string::npos) << e.what();
        }
    };
    // The old format with both names and one value: the two names disagree, so the file is refused.
    expectError("name,alias,value,unit\nEX0C,dxCZ,-15,um\nEC0Y,gXY,3,arcsec\n", {"d.csv:3", "EC0Y = -gXY", "alias_value"});
    // alias_value that contradicts the ISO value.
    expectError("name,alias,value,unit,alias_value\nEC0Y,gXY,-3,arcsec,-3\n", {"d.csv:2", "alias_value", "gXY"});
    // The same deviation twice, once under each name.
    expectError("name,alias,value,unit\nEC0Y,,-3,arcsec\ngXY,,3,arcsec\n", {"d.csv:3", "given twice (first on line 2)"});
    // Where the names agree, both columns and no alias_value are fine.
    test::writeText(dir.file("ok.csv"), "name,alias,value,unit\nEX0C,dxCZ,-15,um\n");
    EXPECT_NEAR(readDeviationCsv(dir.file("ok.csv"), m).get("dxCZ"), -0.015, 1e-15);
}

TEST(IsoNames, SetByNameKeepsTheOtherIsoValues) {
    const MachineModel& m = test::multitasking();
    DeviationSet d(m);
    d.set("EA0C", 3 * kArcsec);
    d.set("EA0Z", -5 * kArcsec);  // turns the reference: aCZ moves with it so that EA0C stays
    EXPECT_NEAR(d.get("EA0C"), 3 * kArcsec, 1e-18);
    EXPECT_NEAR(d.get("aCZ"), 8 * kArcsec, 1e-18);
    d.set("aYZ", 0.0);  // by alias: the other link values stay
    EXPECT_NEAR(d.get("aCZ"), 8 * kArcsec, 1e-18);
    EXPECT_NEAR(d.get("EA0C"), 8 * kArcsec, 1e-18);
}

TEST(IsoNames, EveryControllerFileIsTheSameFromEitherSpelling) {
    // Emit with every backend from a CSV in ISO names and from one in paper aliases describing the same machine; the
    // files must be identical byte for byte (a backend that refuses the machine must refuse both the same way).
    struct Case {
        const char* machine;
        std::string iso, paper;
    };
    const std::vector<Case> cases{
        {"multitasking",
         "name,value,unit\nEX0C1,12,um\nEZ0C1,-8,um\nEA0C1,6.5,arcsec\nEA0B,-4,arcsec\nEB0B,9,arcsec\nEC0B,-7.5,arcsec\n"
         "EC0Y,-3,arcsec\nEA0Z,-5,arcsec\nEB0Z,6,arcsec\nEX0C,-15,um\nEY0C,10,um\nEA0C,3,arcsec\nEB0C,0.5,arcsec\n",
         "alias,value,unit\ndxBT,12,um\ndzBT,-8,um\naBT,6.5,arcsec\naXB,-4,arcsec\nbXB,9,arcsec\ngXB,-7.5,arcsec\n"
         "gXY,3,arcsec\naYZ,5,arcsec\nbYZ,-6,arcsec\ndxCZ,-15,um\ndyCZ,10,um\naCZ,8,arcsec\nbCZ,-5.5,arcsec\n"},
        {"table-table-ac",
         "name,value,unit\nEY0A,18,um\nEC0A,-8,arcsec\nEX0C,14,um\nEC0Y,-4,arcsec\nEB0Z,-3,arcsec\nEA0Z,2.5,arcsec\n",
         "name,value,unit\nEY0A,18,um\nEC0A,-8,arcsec\nEX0C,14,um\nCXY,4,arcsec\nCZX,-3,arcsec\nCYZ,-2.5,arcsec\n"},
        // The head's orientation is read relative to the reference frame: EA0B = eBz + [Z.a], EC0B = exB + [Y.c].
        {"tilting-head-b", "name,value,unit\nEA0Z,2,arcsec\nEC0Y,1,arcsec\nEA0B,8.5,arcsec\nEC0B,-3,arcsec\nEX0B,7,um\n",
         "name,value,unit\nEA0Z,2,arcsec\nEC0Y,1,arcsec\neBz,6.5,arcsec\nexB,-4,arcsec\nEX0B,7,um\n"},
    };
    test::ScratchDir dir("iso-emit");
    int compared = 0;
    for (const Case& c : cases) {
        const MachineModel m = sample(c.machine);
        test::writeText(dir.file("iso.csv"), "# cnccomp-deviations/2\n" + c.iso);
        test::writeText(dir.file("paper.csv"), "# cnccomp-deviations/2\n" + c.paper);
        const DeviationSet a = readDeviationCsv(dir.file("iso.csv"), m), b = readDeviationCsv(dir.file("paper.csv"), m);
        for (const controllers::Backend* be : controllers::backends()) {
            std::string errA, errB;
            controllers::EmitResult ra, rb;
            try {
                ra = be->emit({m, a, "truth.csv", "2024-01-01"});
            } catch (const std::exception& e) {
                errA = e.what();
            }
            try {
                rb = be->emit({m, b, "truth.csv", "2024-01-01"});
            } catch (const std::exception& e) {
                errB = e.what();
            }
            EXPECT_EQ(errA, errB) << be->name() << " " << c.machine;
            ASSERT_EQ(ra.files.size(), rb.files.size()) << be->name();
            for (size_t i = 0; i < ra.files.size(); ++i) {
                EXPECT_EQ(ra.files[i].name, rb.files[i].name);
                EXPECT_EQ(ra.files[i].content, rb.files[i].content) << be->name() << " " << c.machine << " " << ra.files[i].name;
                ++compared;
            }
        }
    }
    EXPECT_GE(compared, 15);
}

TEST(IsoNames, MachinesWhoseNamesCannotMeanWhatTheySayAreRefused) {
    test::ScratchDir dir("iso-machine");
    const auto machine = [&](const std::string& devs) {
        test::writeText(dir.file("m.xml"), R"(<?xml version="1.0"?>
<machine name="m">
  <workpiece><axis name="C" type="rotary" direction="0 0 1" min="-360" max="360"/></workpiece>
  <tool direction="0 0 -1">
    <axis name="Z" type="linear" direction="0 0 1" min="-500" max="500"/>
    <axis name="Y" type="linear" direction="0 1 0" min="-500" max="500"/>
    <axis name="X" type="linear" direction="1 0 0" min="-500" max="500"/>
  </tool>
  <deviations>)" + devs + R"(</deviations>
</machine>
)");
        return dir.file("m.xml");
    };
    const auto expectError = [&](const std::string& devs, const char* part) {
        try {
            readMachineXml(machine(devs));
            ADD_FAILURE() << "accepted " << devs;
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
        }
    };
    // A rotation of Z about Z cannot turn Y relative to X.
    expectError(R"(<location name="EC0Y" link="Z" component="c"/>)", "does not change the quantity ISO 230-1 calls EC0Y");
    // One squareness per pair.
    expectError(R"(<location name="EC0Y" link="X" component="c"/><location name="EC0X" link="Y" component="c"/>)",
                "both EC0X and EC0Y");
    expectError(R"(<location name="EA0C" alias="aCZ" alias-sign="2" link="C" component="a"/>)", "alias-sign '2'");
    expectError(R"(<location name="EA0C" alias-sign="-1" link="C" component="a"/>)", "alias-sign without an alias");
    // X primary: EC0X declared makes Y the reference for rotations about Z, so EC0X = −(Y turned about Z relative to X).
    const MachineModel m = readMachineXml(machine(R"(<location name="EC0X" link="X" component="c"/>)"));
    DeviationSet d(m);
    d.setLinkValue("EC0X", 4 * kArcsec);
    EXPECT_NEAR(d.get("EC0X"), 4 * kArcsec, 1e-18);
}

}  // namespace
}  // namespace cnccomp
