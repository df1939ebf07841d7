// Identity: under an all-zero deviation set (a deviation file with only its header) the corrected program is
// byte-identical to the input, for every program in samples/gcode and every real-world program in
// ../shared/gcode-corpus (read in place, never copied).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "postproc/correct_program.hpp"
#include "test_support.hpp"

namespace cnccomp::postproc {
using namespace cnccomp::io;
namespace {

namespace fs = std::filesystem;

const MachineModel& machineFor(const std::string& file) {
    static const MachineModel table = readMachineXml(test::sourcePath("samples/machines/table-table-ac.xml"));
    static const MachineModel head = readMachineXml(test::sourcePath("samples/machines/tilting-head-b.xml"));
    if (file.find("table-table") != std::string::npos) return table;
    if (file.find("printer") != std::string::npos || file.find("cura") != std::string::npos) return head;
    return test::multitasking();
}

std::vector<fs::path> programsIn(const fs::path& dir) {
    std::vector<fs::path> files;
    if (!fs::is_directory(dir)) return files;
    for (const auto& e : fs::directory_iterator(dir))
        if (e.is_regular_file() && e.path().extension() != ".md") files.push_back(e.path());
    std::sort(files.begin(), files.end());
    return files;
}

/// Corrects `file` with an all-zero set read from a header-only CSV; returns the output bytes.
std::string correctWithZeroSet(const fs::path& file, const MachineModel& m, CorrectSummary& s) {
    test::ScratchDir dir("pp-identity");
    test::writeText(dir.file("zero.csv"), "name,alias,value,unit\n");
    const DeviationSet d = readDeviationCsv(dir.file("zero.csv"), m);
    std::ifstream in(file, std::ios::binary);
    std::ostringstream out;
    CorrectOptions o;
    o.inputName = file.string();
    o.setup.addToolLength("100");
    s = correctProgram(m, d, in, out, o);
    return out.str();
}

void expectIdentity(const fs::path& file) {
    const MachineModel& m = machineFor(file.filename().string());
    CorrectSummary s;
    const std::string out = correctWithZeroSet(file, m, s);
    const std::string in = test::readText(file.string());
    ASSERT_EQ(out.size(), in.size()) << file;
    EXPECT_TRUE(out == in) << file << ": output differs from input";
    EXPECT_EQ(s.corrected, 0u) << file;
    EXPECT_EQ(s.addedLines, 0u) << file;
    EXPECT_EQ(s.bytesIn, in.size());
}

TEST(PostprocIdentity, EverySampleProgramIsReproducedByteForByte) {
    const auto files = programsIn(test::sourcePath("samples/gcode"));
    ASSERT_GE(files.size(), 6u) << "samples/gcode should hold the sample programs";
    for (const auto& f : files) expectIdentity(f);
}

TEST(PostprocIdentity, EveryCorpusProgramIsReproducedByteForByte) {
    const fs::path corpus = test::sharedPath("gcode-corpus");
    if (!fs::is_directory(corpus)) GTEST_SKIP() << "no " << corpus << ": corpus identity not checked";
    const auto files = programsIn(corpus);
    ASSERT_FALSE(files.empty());
    for (const auto& f : files) expectIdentity(f);
}

TEST(PostprocIdentity, SampleProgramsAreActuallyEvaluated) {
    // Identity must come from a pipeline that reads the programs, not from skipping them.
    CorrectSummary s;
    correctWithZeroSet(test::sourcePath("samples/gcode/multitasking-5axis.ngc"), test::multitasking(), s);
    EXPECT_GE(s.moves, 90u);
    EXPECT_EQ(s.passedThrough, 0u);
    correctWithZeroSet(test::sourcePath("samples/gcode/fanuc-macro.nc"), test::multitasking(), s);
    EXPECT_EQ(s.dialect, Dialect::Fanuc);
    EXPECT_GE(s.passedThrough, 15u);  // macros, calls, loops, TCP, cycles: reported
    EXPECT_GE(s.moves, 5u);
}

TEST(PostprocIdentity, CommandLineWritesAnIdenticalFile) {
    test::ScratchDir dir("pp-identity-cli");
    test::writeText(dir.file("zero.csv"), "name,alias,value,unit\n");
    const std::string in = test::sourcePath("samples/gcode/table-table-ac-5axis.ngc");
    const auto r = test::runCli("correct --machine " + test::sourcePath("samples/machines/table-table-ac.xml") +
                                " --deviations " + dir.file("zero.csv") + " --in " + in + " --out " + dir.file("out.ngc"));
    ASSERT_EQ(r.exitCode, 0) << r.out;
    EXPECT_EQ(test::readText(dir.file("out.ngc")), test::readText(in));  // CRLF kept
    EXPECT_NE(r.out.find("blocks corrected: 0"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace cnccomp::postproc
