#pragma once
// Helpers shared by the tests of the siemens-840d, heidenhain-tnc and fanuc-30i backends: golden files,
// workspace samples away from singular orientations, random deviation sets, figures printed for the report.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <set>
#include <string>

#include <fmt/format.h>

#include "cnccomp/inverse_kinematics.hpp"
#include "controllers/common/evaluate.hpp"
#include "test_support.hpp"

namespace cnccomp::test {

/// Workspace samples (controllers/common/evaluate) without the poses where the tool axis is (nearly)
/// parallel to a rotary axis: there the TCP has no unique answer (e.g. C at B = 0 on seed 000's machine).
inline std::vector<AxisVector> nonSingularSamples(const MachineModel& m, int perAxis, double maxLinear = 200.0) {
    const Kinematics k(m);
    std::vector<AxisVector> out;
    for (const AxisVector& q : controllers::workspaceSamples(m, perAxis, maxLinear)) {
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
        if (def.kind == DeviationKind::Location) d.set(def.name, def.isAngle() ? u(rng) * arcsec * kArcsec : u(rng) * um * kUm);
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
            d.set(def.name, def.isAngle() ? v * kArcsec : v * kUm);
            ++i;
        }
    return d;
}

inline void report(const std::string& label, const controllers::CompensationFigures& f) {
    std::printf("[figures] %-48s points %5d  max %8.3f -> %8.5f um (%.2f %% left)  rms %8.3f -> %8.5f um  axis %.2f -> %.4f arcsec\n",
                label.c_str(), f.points, f.maxBefore / kUm, f.maxAfter / kUm,
                f.maxBefore > 0 ? 100.0 * f.maxAfter / f.maxBefore : 0.0, f.rmsBefore / kUm, f.rmsAfter / kUm,
                f.maxAxisBefore / kArcsec, f.maxAxisAfter / kArcsec);
}

inline controllers::CompensationFigures evaluateBackend(const controllers::Backend& b, const MachineModel& m,
                                                        const DeviationSet& truth,
                                                        const std::vector<AxisVector>& samples, double toolLength) {
    return controllers::emitApplyEvaluate(b, m, truth, samples, toolLength);
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
