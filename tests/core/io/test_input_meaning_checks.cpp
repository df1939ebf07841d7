// Inputs whose meaning the numbers alone do not show: a plan feed that is not the real one on
// time-sampled files, deviation files written before the ISO names took ISO 230-1's meaning, and `compare` of two files
// that name the same machine differently. Oracles: the simulator's known feed and geometry (round trips), and the
// ISO meaning of the names (iso_names.hpp) as the deviation tests of that module check it.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "test_support.hpp"

namespace cnccomp {
using namespace cnccomp::io;
namespace {

const std::string kFormat = "# cnccomp-deviations/2: location errors under ISO 230-1 names are ISO values (iso_names.hpp)\n";

std::string replaceAll(std::string s, const std::string& a, const std::string& b) {
    for (size_t p = s.find(a); p != std::string::npos; p = s.find(a, p + b.size())) s.replace(p, a.size(), b);
    return s;
}

// The recorded quickstart plan says feed 1000; the files were recorded at 1000. A plan that says 1020 (2 % above the
// real feed) is refused with the feed the data give; the right plan reports that feed.
TEST(InputMeaning, PlanFeedOffTheRealOneIsRefused) {
    test::ScratchDir dir("feed-check");
    const std::string m = test::sourcePath("samples/machines/multitasking.xml");
    const std::string p = test::sourcePath("samples/plans/multitasking-six-circles-recorded.xml");
    const auto sim = test::runCli(fmt::format("simulate --machine {} --plan {} --deviations {} --noise-um 0.2 --seed 1 "
                                              "--instrument time --out {}",
                                              m, p, test::sourcePath("samples/deviations/multitasking-truth.csv"), dir.file("t")));
    ASSERT_EQ(sim.exitCode, 0) << sim.out;
    const auto ok = test::runCli(fmt::format("identify --machine {} --plan {} --traces {} --out {}", m, p, dir.file("t"),
                                             dir.file("d.csv")));
    ASSERT_EQ(ok.exitCode, 0) << ok.out;
    EXPECT_NE(ok.out.find("feed from the data, run B-X: 1000.0 mm/min (plan 1000"), std::string::npos) << ok.out;
    // A real instrument's file does not say the feed (cnccomp's own files carry '# feed:', checked against the plan).
    std::filesystem::create_directory(dir.file("raw"));
    for (const auto& e : std::filesystem::directory_iterator(dir.file("t"))) {
        std::istringstream in(test::readText(e.path().string()));
        std::string line, text;
        while (std::getline(in, line))
            if (line.rfind("# feed", 0) != 0) text += line + "\n";
        test::writeText(dir.file("raw/" + e.path().filename().string()), text);
    }
    for (const char* wrong : {"1010", "1020", "1050", "980"}) {
        test::writeText(dir.file("p.xml"), replaceAll(test::readText(p), "feed=\"1000\"", fmt::format("feed=\"{}\"", wrong)));
        const auto bad = test::runCli(fmt::format("identify --machine {} --plan {} --traces {} --out {}", m,
                                                  dir.file("p.xml"), dir.file("raw"), dir.file("d2.csv")));
        EXPECT_EQ(bad.exitCode, 2) << wrong << ": " << bad.out;
        EXPECT_NE(bad.out.find("B-X.csv:"), std::string::npos) << bad.out;
        EXPECT_NE(bad.out.find("The data give a feed of 1000.0 mm/min"), std::string::npos) << bad.out;
        EXPECT_NE(bad.out.find("feed=\"1000.0\""), std::string::npos) << bad.out;
        EXPECT_FALSE(std::filesystem::exists(dir.file("d2.csv")));
    }
    // A file whose own '# feed:' line agrees with the wrong plan (the programmed feed, while the override ran the
    // machine at 1000) is refused by the data as well: the line is checked against the plan, the data against both.
    std::filesystem::create_directory(dir.file("said"));
    for (const auto& e : std::filesystem::directory_iterator(dir.file("t")))
        test::writeText(dir.file("said/" + e.path().filename().string()),
                        replaceAll(test::readText(e.path().string()), "# feed: 1000\n", "# feed: 1020\n"));
    test::writeText(dir.file("p.xml"), replaceAll(test::readText(p), "feed=\"1000\"", "feed=\"1020\""));
    const auto said = test::runCli(fmt::format("identify --machine {} --plan {} --traces {} --out {}", m, dir.file("p.xml"),
                                               dir.file("said"), dir.file("d3.csv")));
    EXPECT_EQ(said.exitCode, 2) << said.out;
    EXPECT_NE(said.out.find("The data give a feed of 1000.0 mm/min"), std::string::npos) << said.out;
    EXPECT_FALSE(std::filesystem::exists(dir.file("d3.csv")));
}

// A 4-column, names-only file without the format line, on the B/C machine where EC0Y and EC0B changed meaning: refused
// with the line and the conversion; the same rows under the format line are read as ISO values.
TEST(InputMeaning, OldDeviationFileIsRefusedWithTheConversion) {
    test::ScratchDir dir("old-deviations");
    const MachineModel& m = test::sampleMachine("table-table-bc");
    const std::string rows = "name,alias,value,unit\nEX0B,,7,um\nEC0B,,-8,arcsec\nEB0C,,-9,arcsec\nEC0Y,,-3,arcsec\nEB0Z,,6,arcsec\n";
    test::writeText(dir.file("old.csv"), rows);
    try {
        readDeviationCsv(dir.file("old.csv"), m);
        ADD_FAILURE() << "an old-layout file was read with the new meaning";
    } catch (const InputError& e) {
        const std::string w = e.what();
        EXPECT_NE(w.find("old.csv:2"), std::string::npos) << w;
        EXPECT_NE(w.find("no format line"), std::string::npos) << w;
        EXPECT_NE(w.find("EC0Y"), std::string::npos) << w;
        EXPECT_NE(w.find("# cnccomp-deviations/2"), std::string::npos) << w;
    }
    test::writeText(dir.file("new.csv"), kFormat + rows);
    const DeviationSet d = readDeviationCsv(dir.file("new.csv"), m);
    EXPECT_NEAR(d.isoValue(d.require("EC0Y")), -3 * kArcsec, 1e-12);
    // The same file saved by a spreadsheet as "CSV UTF-8" (a byte-order mark before the format line) is still the new
    // layout: the format line is found behind the mark (it was not, and the file was refused as an old one).
    test::writeText(dir.file("bom.csv"), "\xEF\xBB\xBF" + kFormat + rows);
    EXPECT_NEAR(readDeviationCsv(dir.file("bom.csv"), m).isoValue(d.require("EC0Y")), -3 * kArcsec, 1e-12);
    // What cnccomp writes carries the line and reads back to the same geometry.
    const std::string written = formatDeviationCsv(d);
    EXPECT_EQ(written.rfind(kFormat, 0), 0u) << written;
    test::writeText(dir.file("w.csv"), written);
    const DeviationSet back = readDeviationCsv(dir.file("w.csv"), m);
    for (Eigen::Index i = 0; i < d.values.size(); ++i) EXPECT_NEAR(back.values[i], d.values[i], 1e-12);
    // A file whose names mean the same in both readings needs no line (only component rows here).
    test::writeText(dir.file("comp.csv"), "name,alias,value,unit\nEXC[1],,2,um\n");
    EXPECT_NO_THROW(readDeviationCsv(dir.file("comp.csv"), m));
    // The CLI: exit 2 with the file and line.
    const auto r = test::runCli(fmt::format("compare --machine {} --truth {} --estimate {}",
                                            test::sourcePath("samples/machines/table-table-bc.xml"), dir.file("new.csv"),
                                            dir.file("old.csv")));
    EXPECT_EQ(r.exitCode, 2) << r.out;
    EXPECT_NE(r.out.find("old.csv:2"), std::string::npos) << r.out;
}

// A truth given by aliases and an estimate by ISO names: the names both list agree, the geometry does not. compare lists
// the implied difference instead of "largest difference 0.0000".
TEST(InputMeaning, CompareComparesTheImpliedGeometry) {
    test::ScratchDir dir("compare-implied");
    const std::string m = test::sourcePath("samples/machines/multitasking.xml");
    const MachineModel& mm = test::multitasking();
    test::writeText(dir.file("truth.csv"), kFormat + "name,alias,value,unit\n,aYZ,5,arcsec\n");
    const DeviationSet truth = readDeviationCsv(dir.file("truth.csv"), mm);
    const double isoEA0Z = truth.isoValue(truth.require("EA0Z")) / kArcsec;
    test::writeText(dir.file("est.csv"), kFormat + fmt::format("name,alias,value,unit\nEA0Z,,{:.6f},arcsec\n", isoEA0Z));
    const auto r = test::runCli(fmt::format("compare --machine {} --truth {} --estimate {}", m, dir.file("truth.csv"),
                                            dir.file("est.csv")));
    ASSERT_EQ(r.exitCode, 0) << r.out;
    EXPECT_EQ(r.out.find("largest difference: 0.0000 um, 0.0000 arcsec"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("implied by the names the files use"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("5.0000"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("the machines differ there"), std::string::npos) << r.out;
    // The same geometry under both spellings compares equal.
    const auto same = test::runCli(fmt::format("compare --machine {} --truth {} --estimate {}", m, dir.file("truth.csv"),
                                               dir.file("truth.csv")));
    EXPECT_NE(same.out.find("largest difference: 0.0000 um, 0.0000 arcsec"), std::string::npos) << same.out;
}

}  // namespace
}  // namespace cnccomp
