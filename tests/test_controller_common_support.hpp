#pragma once
// Helpers shared by the backend tests (LinuxCNC, ISG, generic): sample machines and deviation sets, the subset a
// backend claims to compensate, golden-file comparison.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <map>

#include "cnccomp/error.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "controllers/backend.hpp"
#include "controllers/common/files.hpp"
#include "test_support.hpp"

namespace cnccomp::controllers::testing {

struct Sample {
    std::string machine, deviations;
};

inline const MachineModel& machine(const std::string& name) {
    static std::map<std::string, MachineModel> cache;
    auto it = cache.find(name);
    if (it == cache.end()) it = cache.emplace(name, io::readMachineXml(test::sourcePath("samples/machines/" + name + ".xml"))).first;
    return it->second;
}

inline DeviationSet deviations(const Sample& s) {
    return io::readDeviationCsv(test::sourcePath("samples/deviations/" + s.deviations + ".csv"), machine(s.machine));
}

/// The deviation set with only the deviations the backend lists as compensated.
inline DeviationSet claimedOnly(const DeviationSet& d, const EmitResult& r) {
    DeviationSet out = d;
    const MachineModel& m = d.machine();
    for (const Coverage& c : r.notCompensated) {
        const int i = m.deviationIndex(c.deviation);
        const DeviationDef& def = m.deviations[i];
        out.values.segment(def.offset, def.size()).setZero();
        out.present[i] = 0;
    }
    return out;
}

inline EmitResult emitSample(const std::string& backendName, const Sample& s, const DeviationSet& d) {
    return backend(backendName).emit({machine(s.machine), d, s.deviations + ".csv", "2024-01-01"});
}

/// Compares emitted files with tests/data/controllers/<family>/<machine>/ (rewritten when CNCCOMP_UPDATE_GOLDEN is
/// set) and returns the golden files as read from disk.
inline std::vector<OutputFile> compareWithGolden(const std::string& family, const std::string& machineName,
                                                 const EmitResult& r) {
    const std::filesystem::path dir = test::sourcePath("tests/data/controllers/" + family + "/" + machineName);
    if (std::getenv("CNCCOMP_UPDATE_GOLDEN")) {
        std::filesystem::remove_all(dir);
        std::filesystem::create_directories(dir);
        for (const OutputFile& f : r.files) test::writeText((dir / f.name).string(), f.content);
    }
    std::vector<OutputFile> golden;
    for (const auto& e : std::filesystem::directory_iterator(dir))
        golden.push_back({e.path().filename().string(), test::readText(e.path().string())});
    EXPECT_EQ(golden.size(), r.files.size()) << family << "/" << machineName;
    for (const OutputFile& f : r.files) {
        const OutputFile* g = common::findFile(golden, f.name);
        EXPECT_NE(g, nullptr) << family << "/" << machineName << "/" << f.name;
        if (g) {
            EXPECT_TRUE(g->content == f.content) << family << "/" << machineName << "/" << f.name << " differs from the golden";
        }
    }
    return golden;
}

/// Line number of the InputError thrown by f, or -1.
template <class F>
int inputErrorLine(F f) {
    try {
        f();
    } catch (const InputError& e) {
        return e.line();
    }
    return -1;
}

}  // namespace cnccomp::controllers::testing
