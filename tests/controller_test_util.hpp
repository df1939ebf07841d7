#pragma once
// Helpers shared by the tests of the siemens-840d, heidenhain-tnc and fanuc-30i backends: golden files,
// workspace samples away from singular orientations, random deviation sets, figures printed for the report.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <random>
#include <set>
#include <string>

#include <fmt/format.h>

#include "cnccomp/inverse_kinematics.hpp"
#include "controllers/common/evaluate.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "test_support.hpp"

namespace cnccomp::test {

/// Workspace samples (controllers/common/evaluate) without the poses where the tool axis is (nearly)
/// parallel to a rotary axis: there the TCP has no unique answer (e.g. C at B = 0 on [MultiTasking]'s machine).
inline std::vector<AxisVector> nonSingularSamples(const MachineModel& m, int perAxis, double maxLinear = 200.0) {
    const Kinematics k(m);
    std::vector<AxisVector> out;
    for (const AxisVector& q : controllers::common::workspaceSamples(m, perAxis, maxLinear)) {
        const Pose bMt = k.baseToTool(q);
        const Vec3 axis = bMt.linear() * m.toolDirection;
        bool ok = true;
        for (const JointFrame& j : k.jointFrames(q))
            if (j.rotary && j.direction.cross(axis).norm() < 0.1) ok = false;
        if (ok) out.push_back(q);
    }
    return out;
}

/// Every location deviation of the machine at a random value (±30 um, ±50 arcsec), all marked present.
inline DeviationSet randomLocationErrors(const MachineModel& m, unsigned seed, double um = 30.0, double arcsec = 50.0) {
    DeviationSet d(m);
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-1, 1);
    for (const auto& def : m.deviations)
        if (def.kind == DeviationKind::Location) d.setLinkValue(def.name, def.isAngle() ? u(rng) * arcsec * kArcsec : u(rng) * um * kUm);
    return d;
}

/// A machine whose table moves (X under a C table) while the column carries Y, Z and a swivel B head: linear
/// axes on both chains, to check signs of the table-side trims. Location errors incl. squareness of the table X
/// slide, and component errors of the table X.
inline MachineModel tableXMachine() {
    static const char* xml = R"(<?xml version="1.0"?>
<machine name="table-x" description="test: X moves the table, C on it; Y Z B on the column">
  <workpiece>
    <axis name="X" type="linear" direction="1 0 0" min="-400" max="400"/>
    <axis name="C" type="rotary" direction="0 0 1" min="-3600" max="3600" modulo="true"/>
  </workpiece>
  <tool direction="0 0 -1">
    <axis name="Y" type="linear" direction="0 1 0" min="-300" max="300"/>
    <axis name="Z" type="linear" direction="0 0 1" min="-200" max="500"/>
    <axis name="B" type="rotary" direction="0 1 0" min="-110" max="110"/>
    <fixed name="S" offset="0 0 -120"/>
  </tool>
  <deviations>
    <location name="EC0X" link="X" component="c" description="squareness of the table X to the column Y"/>
    <location name="EB0X" link="X" component="b" description="squareness of the table X to Z"/>
    <location name="EA0Z" link="Z" component="a" description="squareness Y to Z"/>
    <location name="EX0C" link="C" component="x"/>
    <location name="EY0C" link="C" component="y"/>
    <location name="EA0C" link="C" component="a"/>
    <location name="EX0B" link="B" component="x"/>
    <location name="EZ0B" link="B" component="z"/>
    <location name="EC0B" link="B" component="c"/>
    <location name="EX0S" link="S" component="x"/>
    <component name="EXX" link="X" component="x" basis="polynomial" order="2"/>
    <component name="EYX" link="X" component="y" basis="polynomial" order="2"/>
    <component name="EZX" link="X" component="z" basis="polynomial" order="1"/>
  </deviations>
</machine>
)";
    ScratchDir dir("table-x");
    writeText(dir.file("table-x.xml"), xml);
    return io::readMachineXml(dir.file("table-x.xml"));
}

/// tableXMachine() with every deviation set: location errors patterned, component coefficients fixed.
inline DeviationSet tableXErrors(const MachineModel& m) {
    DeviationSet d(m);
    int i = 0;
    for (const auto& def : m.deviations) {
        const int di = static_cast<int>(&def - m.deviations.data());
        if (def.kind == DeviationKind::Location) {
            const double v = (i % 2 ? -1.0 : 1.0) * (6.0 + 2.0 * i);
            d.setLinkValue(def.name, def.isAngle() ? v * kArcsec : v * kUm);
            ++i;
            continue;
        }
        d.values[def.offset] = (def.name == "EXX" ? 25.0 : def.name == "EYX" ? -15.0 : 10.0) * 1e-6;  // 25 um/m ...
        if (def.size() > 1) d.values[def.offset + 1] = (def.name == "EXX" ? 2e-8 : -3e-8);          // mm per mm^2
        d.present[di] = 1;
    }
    return d;
}

/// Every location deviation at a fixed, recognisable value: ±(5 + 3i) um or arcsec for the i-th deviation,
/// alternating signs (deterministic input for golden files).
inline DeviationSet patternedLocationErrors(const MachineModel& m) {
    DeviationSet d(m);
    int i = 0;
    for (const auto& def : m.deviations)
        if (def.kind == DeviationKind::Location) {
            const double v = (i % 2 ? -1.0 : 1.0) * (5.0 + 3.0 * i);
            d.setLinkValue(def.name, def.isAngle() ? v * kArcsec : v * kUm);
            ++i;
        }
    return d;
}

/// A copy of a machine whose controller counts some axes from another zero: `zeros` maps axis names to the
/// machine-zero attribute (mm, or deg for rotary axes). Nothing else changes: the same physical machine.
inline MachineModel withMachineZero(const MachineModel& m, const std::map<std::string, double>& zeros) {
    MachineModel out = m;
    for (Chain* c : {&out.workpiece, &out.tool})
        for (Link& l : c->links)
            if (const auto it = zeros.find(l.name); it != zeros.end() && l.axisIndex >= 0)
                l.machineZero = l.kind == AxisKind::Rotary ? it->second * kDeg : it->second;
    out.name = m.name + "-machine-zero";
    return out;
}

/// The same deviation values for another model of the same machine (e.g. withMachineZero's copy).
inline DeviationSet sameDeviations(const DeviationSet& d, const MachineModel& other) {
    DeviationSet out(other);
    out.values = d.values;
    out.present = d.present;
    return out;
}

inline void report(const std::string& label, const controllers::common::CompensationFigures& f) {
    std::printf("[figures] %-48s points %5d  max %8.3f -> %8.5f um (%.2f %% left)  rms %8.3f -> %8.5f um  axis %.2f -> %.4f arcsec\n",
                label.c_str(), f.points, f.maxBefore / kUm, f.maxAfter / kUm,
                f.maxBefore > 0 ? 100.0 * f.maxAfter / f.maxBefore : 0.0, f.rmsBefore / kUm, f.rmsAfter / kUm,
                f.maxAxisBefore / kArcsec, f.maxAxisAfter / kArcsec);
}

inline controllers::common::CompensationFigures evaluateBackend(const controllers::Backend& b, const MachineModel& m,
                                                        const DeviationSet& truth,
                                                        const std::vector<AxisVector>& samples, double toolLength) {
    return controllers::common::emitApplyEvaluate(b, m, truth, samples, toolLength);
}

/// Emits with a fixed date and compares every file with tests/data/controllers/<dir>/<name> (byte for byte;
/// CNCCOMP_UPDATE_GOLDEN=1 rewrites them). The golden files are then read back by the backend's reader and
/// must give the same drive commands as the freshly emitted ones.
inline void checkGolden(const controllers::Backend& b, const MachineModel& m, const DeviationSet& d,
                        const std::string& source, const std::string& dir) {
    namespace fs = std::filesystem;
    const controllers::EmitResult r = b.emit({m, d, source, "2024-01-01"});
    const fs::path folder = fs::path(sourcePath("tests/data/controllers")) / dir;
    const bool update = std::getenv("CNCCOMP_UPDATE_GOLDEN") != nullptr;
    if (update) {
        fs::create_directories(folder);
        for (const auto& e : fs::directory_iterator(folder)) fs::remove(e.path());
        for (const auto& f : r.files) writeText((folder / f.name).string(), f.content);
    }
    std::set<std::string> names;
    std::vector<controllers::OutputFile> golden;
    for (const auto& e : fs::directory_iterator(folder)) {
        names.insert(e.path().filename().string());
        golden.push_back({e.path().filename().string(), readText(e.path().string())});
    }
    std::set<std::string> emitted;
    for (const auto& f : r.files) emitted.insert(f.name);
    EXPECT_EQ(names, emitted) << dir;
    for (const auto& f : r.files) {
        const std::string want = readText((folder / f.name).string());
        EXPECT_EQ(f.content, want) << dir << "/" << f.name << " differs from the golden file (CNCCOMP_UPDATE_GOLDEN=1 rewrites)";
    }
    const auto fromGolden = b.apply(m, golden);
    const auto fromEmit = b.apply(m, r.files);
    ASSERT_TRUE(fromGolden && fromEmit);
    for (const AxisVector& q : nonSingularSamples(m, 3)) {
        const AxisVector a = fromGolden->driveCommands(q), c = fromEmit->driveCommands(q);
        EXPECT_LT((a - c).norm(), 1e-9) << dir;
    }
}

/// Text with line `line` (1-based) replaced.
inline std::string replaceLine(const std::string& text, int line, const std::string& with) {
    std::string out;
    int n = 1;
    size_t pos = 0;
    while (pos <= text.size()) {
        const size_t eol = text.find('\n', pos);
        const std::string l = text.substr(pos, eol == std::string::npos ? std::string::npos : eol - pos);
        out += n == line ? with : l;
        if (eol == std::string::npos) break;
        out += '\n';
        pos = eol + 1;
        ++n;
    }
    return out;
}

/// 1-based number of the first line containing `needle`, or 0.
inline int lineOf(const std::string& text, const std::string& needle) {
    const size_t p = text.find(needle);
    if (p == std::string::npos) return 0;
    return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(p), '\n'));
}

}  // namespace cnccomp::test
