// `correct` on one thread and on two (front end and back end pipelined, CorrectOptions::threads) writes the same bytes,
// the same report and the same summary: the real impeller in TCP mode, and a generated joint-mode program long enough
// for many hand-over batches with pass-through blocks, arcs, warnings and a line longer than the read buffer.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>

#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "postproc/correct_program.hpp"
#include "test_postproc_xyzac.hpp"
#include "test_support.hpp"

namespace cnccomp::postproc {
using namespace cnccomp::io;
namespace {

struct Run {
    std::string out, report, summary;
};

Run correctWith(const MachineModel& m, const DeviationSet& d, const std::string& program, CorrectOptions o, int threads) {
    o.threads = threads;
    std::ostringstream report;
    o.report = &report;
    std::istringstream in(program);
    std::ostringstream out;
    const CorrectSummary s = correctProgram(m, d, in, out, o);
    return {out.str(), report.str(), formatSummary(s, 1000)};
}

void expectSameOnOneAndTwoThreads(const MachineModel& m, const DeviationSet& d, const std::string& program,
                                  const CorrectOptions& o, const char* what) {
    const Run one = correctWith(m, d, program, o, 1), two = correctWith(m, d, program, o, 2);
    EXPECT_NE(one.out, program) << what << ": nothing was corrected, the comparison proves little";
    EXPECT_TRUE(one.out == two.out) << what << ": outputs differ";
    EXPECT_EQ(one.report, two.report) << what;
    EXPECT_EQ(one.summary, two.summary) << what;
    // Twice on two threads: no dependence on timing either.
    EXPECT_TRUE(correctWith(m, d, program, o, 2).out == two.out) << what;
}

TEST(PostprocThreads, ImpellerInTcpModeIsTheSameOnOneAndTwoThreads) {
    const std::string path = test::sharedPath("gcode-corpus/impeller-7bl-xyzac.ngc");
    if (!std::filesystem::exists(path)) GTEST_SKIP() << "no " << path;
    test::ScratchDir dir("pp-threads");
    test::writeText(dir.file("m.xml"), test::kXyzacTrtMachine);
    test::writeText(dir.file("d.csv"), "# cnccomp-deviations/2\nname,alias,value,unit\nEY0A,,8,um\nEZ0A,,-12,um\nEA0A,,12,arcsec\nEB0A,,10,arcsec\n"
                                       "EC0A,,-6,arcsec\nEX0C,,15,um\nEY0C,,-9,um\nEA0C,,7,arcsec\nEB0C,,-5,arcsec\n");
    const MachineModel m = readMachineXml(dir.file("m.xml"));
    const DeviationSet d = readDeviationCsv(dir.file("d.csv"), m);
    CorrectOptions o;
    o.dialect = Dialect::Rs274ngc;
    o.setup.addToolLength("30");
    o.tcpOnM = 428, o.tcpOffM = 429;
    o.corrector.toleranceMm = 0.3 * kUm;  // some moves split
    expectSameOnOneAndTwoThreads(m, d, test::readText(path), o, "impeller");
}

TEST(PostprocThreads, JointModeProgramWithEveryKindOfBlockIsTheSameOnOneAndTwoThreads) {
    const MachineModel& m = test::multitasking();
    const DeviationSet d = readDeviationCsv(test::sourcePath("samples/deviations/multitasking-truth.csv"), m);
    std::string program = "(generated)\nG21 G90 G17 G94\nG0 X50 Y0 Z40 B0 C0\nG1 Z12 F800.\n";
    char buf[160];
    for (int k = 0; k < 3000; ++k) {
        const double c = 0.7 * k, r = c * kDeg;
        std::snprintf(buf, sizeof buf, "X%.4f Y%.4f Z%.4f B%.3f C%.3f\n", 45.0 + 5.0 * std::cos(3 * r), 2.0 * std::sin(r),
                      10.0 + 2.0 * std::sin(2 * r), 20.0 + 25.0 * std::sin(2 * r), std::fmod(c, 360.0));
        program += buf;
        if (k % 500 == 7) program += "#1=5\nG1 X#1\n";                         // passed through, reported
        if (k % 700 == 11) program += "G2 X40 Y10 I-5 J5\nG1 X45 Y0\n";        // an arc
        if (k == 1500) program += "(" + std::string(6000, 'x') + ")\nY3\n";  // longer than the read buffer below
    }
    program += "M30\n";
    CorrectOptions o;
    o.dialect = Dialect::Rs274ngc;
    o.setup.addToolLength("100");
    o.bufferSize = 4096;
    expectSameOnOneAndTwoThreads(m, d, program, o, "joint mode");
}

}  // namespace
}  // namespace cnccomp::postproc
