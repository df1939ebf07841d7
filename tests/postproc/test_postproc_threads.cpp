// `correct` on one thread and on two (front end and back end pipelined, CorrectOptions::threads) writes the same bytes,
// the same report and the same summary: the real impeller in TCP mode, and a generated joint-mode program long enough
// for many hand-over batches with pass-through blocks, arcs, warnings and a line longer than the read buffer. Both run
// the front end in batches (FrontEnd::fill: a batch's blocks read, then placed); that it gives the records one block at
// a time gives (FrontEnd::next) is checked record by record, across TCP switches and long lines.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>

#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "postproc/correct_front_end.hpp"
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

/// Every record of `program` as FrontEnd::next gives them one at a time, or as FrontEnd::fill gives them in batches of
/// `batch`.
std::vector<iso::Record> frontRecords(const MachineModel& m, const DeviationSet& d, const std::string& program,
                                      const CorrectOptions& o, size_t batch) {
    std::istringstream in(program);
    LineReader reader(in, o.bufferSize);
    iso::FrontEnd front(m, d, o, Dialect::Rs274ngc, reader);
    std::vector<iso::Record> all;
    if (batch == 0) {
        iso::Record rec;
        while (front.next(rec)) all.push_back(rec);
        return all;
    }
    std::vector<iso::Record> recs(batch);
    for (bool end = false; !end;) {
        std::exception_ptr error;
        const size_t n = front.fill(recs.data(), batch, size_t{1} << 20, end, error);
        EXPECT_FALSE(error);
        all.insert(all.end(), recs.begin(), recs.begin() + static_cast<std::ptrdiff_t>(n));
    }
    return all;
}

TEST(PostprocThreads, FrontEndInBatchesGivesTheRecordsOfOneBlockAtATime) {
    // The xyzac table machine with its location errors: joint-mode moves with the table tilted and turned, then TCP on
    // (the interpreter re-reads the position in the new mode: a world point far from the joint position, so a batch
    // that read on past the switch before placing it would start the next moves elsewhere), moves that leave axes
    // out, TCP off and on again, a line longer than the read buffer with an axis word (place() forgets the position),
    // and a block the front end refuses.
    test::ScratchDir dir("pp-front-batches");
    test::writeText(dir.file("m.xml"), test::kXyzacTrtMachine);
    test::writeText(dir.file("d.csv"), test::xyzac::kDeviationCsv);
    const MachineModel m = readMachineXml(dir.file("m.xml"));
    const DeviationSet d = readDeviationCsv(dir.file("d.csv"), m);
    std::string program = "G21 G90 G94\nG0 X10 Y5 Z30 A-30 C40\n";
    char buf[200];
    for (int round = 0; round < 6; ++round) {
        for (int k = 0; k < 23; ++k) {
            const double t = 0.1 * k + round;
            std::snprintf(buf, sizeof buf, "G1 X%.3f Y%.3f Z%.3f A%.3f C%.3f F500\n", 10 + 5 * std::cos(t), 5 * std::sin(t),
                          30 - k * 0.2, -30 + 10 * std::sin(t), 40.0 + 7 * k + round);
            program += buf;
        }
        program += "M428\nG1 X2 F300\nY3\nG1 Z25 A-20\n";
        for (int k = 0; k < 17; ++k) {
            std::snprintf(buf, sizeof buf, "G1 X%.3f Y%.3f C%.3f\n", 4 * std::cos(0.3 * k), 4 * std::sin(0.3 * k), 60.0 + 3 * k);
            program += buf;
        }
        if (round == 2) program += "(" + std::string(5000, 'x') + ") G1 X1\nG1 Y2\n";  // longer than the buffer
        if (round == 3) program += "G1 X#1\nG1 Y1\n";                                  // refused: a parameter
        program += "M429\nG1 X12 Y4\n";
    }
    program += "M30\n";
    CorrectOptions o;
    o.dialect = Dialect::Rs274ngc;
    o.setup.addToolLength("30");
    o.tcpOnM = 428, o.tcpOffM = 429;
    o.bufferSize = 4096;
    const std::vector<iso::Record> one = frontRecords(m, d, program, o, 0);
    int tcpMoves = 0, corrected = 0, partial = 0;
    for (const iso::Record& r : one) {
        tcpMoves += r.r.kind == BlockKind::Move && r.space.mode != ProgramMode::Joints;
        corrected += r.corrected;
        partial += r.partial;
    }
    EXPECT_GT(tcpMoves, 100);
    EXPECT_GT(corrected, 200);
    EXPECT_GT(partial, 1);
    for (size_t batch : {1, 3, 16, 64}) {
        const std::vector<iso::Record> b = frontRecords(m, d, program, o, batch);
        ASSERT_EQ(b.size(), one.size()) << "batch " << batch;
        for (size_t k = 0; k < one.size(); ++k) {
            const iso::Record &x = one[k], &y = b[k];
            const std::string at = "batch " + std::to_string(batch) + ", line " + std::to_string(x.number);
            ASSERT_EQ(x.text, y.text) << at;
            ASSERT_EQ(x.partial, y.partial) << at;
            if (x.partial) {
                EXPECT_EQ(x.overlongCode, y.overlongCode) << at;
                EXPECT_EQ(x.overlongModal, y.overlongModal) << at;
                continue;
            }
            ASSERT_EQ(x.r.kind, y.r.kind) << at;
            ASSERT_EQ(x.notices, y.notices) << at;
            if (x.r.kind != BlockKind::Move && !x.frontRefused) continue;
            // Bit for bit: the same computations in the same order.
            EXPECT_TRUE(x.r.start == y.r.start && x.r.end == y.r.end) << at << ": the interpreter's positions differ";
            EXPECT_EQ(x.space.mode, y.space.mode) << at;
            EXPECT_EQ(x.corrected, y.corrected) << at;
            EXPECT_EQ(x.nomStartKnown, y.nomStartKnown) << at;
            EXPECT_TRUE(x.nomStart.p == y.nomStart.p && x.nomEnd.p == y.nomEnd.p) << at;
            if (x.corrected) {
                EXPECT_TRUE(x.cNom == y.cNom && x.cEnd == y.cEnd) << at << ": the corrections differ";
            }
            EXPECT_EQ(x.tipResidual, y.tipResidual) << at;
        }
    }
}

}  // namespace
}  // namespace cnccomp::postproc
