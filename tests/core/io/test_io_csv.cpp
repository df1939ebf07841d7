// The one CSV reader (io/csv.hpp) and what it once misread: a byte-order mark, ';' and decimal commas,
// non-regular files, deviations beyond any machine.
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <future>

#include <gtest/gtest.h>

#include "cnccomp/error.hpp"
#include "cnccomp/io/csv.hpp"
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/text_util.hpp"
#include "cnccomp/io/plan_xml.hpp"
#include "cnccomp/io/trace_import.hpp"
#include "test_support.hpp"

namespace cnccomp {
using namespace cnccomp::io;
namespace {

namespace fs = std::filesystem;

template <typename F>
std::string inputErrorOf(F&& f) {
    try {
        f();
    } catch (const InputError& e) {
        return e.what();
    }
    return "(no InputError)";
}

// Oracle: RFC 4180 (quoting, "" inside quotes) and the files spreadsheets write (BOM, CRLF, ';' in comma locales).
TEST(CsvReader, ReadsTheDialectsSpreadsheetsWrite) {
    const std::string text = "\xEF\xBB\xBF# run: B1\r\nname;\"alias\";value\r\n\r\nEX0C1; \"a;b\" ;\"1,5\"\r\n\"q\"\"x\";;2\r\n";
    CsvTable t = parseCsv(text, "mem.csv");
    EXPECT_EQ(t.separator, ';');
    ASSERT_EQ(t.header.cells.size(), 3u);
    EXPECT_EQ(t.header.cells[0], "name");  // no BOM left in front of it
    EXPECT_EQ(t.header.cells[1], "alias");
    EXPECT_EQ(t.header.line, 2);
    ASSERT_EQ(t.rows.size(), 2u);
    EXPECT_EQ(t.rows[0].line, 4);
    EXPECT_EQ(t.rows[0].cells[1], "a;b");
    EXPECT_DOUBLE_EQ(t.requireNumber(t.rows[0], 2), 1.5);  // decimal comma where ';' separates
    EXPECT_EQ(t.rows[1].cells[0], "q\"x");
    EXPECT_EQ(t.rows[1].cells[1], "");
    t = parseCsv("a\tb\n1\t2\n", "tab.csv");
    EXPECT_EQ(t.separator, '\t');
    EXPECT_DOUBLE_EQ(t.requireNumber(t.rows[0], 1), 2.0);
    const std::string open = inputErrorOf([] { parseCsv("a,b\n\"1,2\n", "q.csv"); });
    EXPECT_NE(open.find("q.csv:2"), std::string::npos) << open;
    EXPECT_NE(open.find("not closed"), std::string::npos) << open;
    const std::string utf16 = inputErrorOf([] { parseCsv(std::string("\xFF\xFE" "a\0,\0b\0", 8), "u.csv"); });
    EXPECT_NE(utf16.find("UTF-16"), std::string::npos) << utf16;
}

// A deviation file saved as "CSV UTF-8" by a spreadsheet (with a BOM, CRLF) reads exactly as the plain file. Oracle:
// the sample file itself, read without the BOM (with the BOM the header's 'name' was not found, the rows
// were read under their paper aliases and five values flipped sign).
TEST(DeviationCsvInput, ByteOrderMarkAndCrlfReadAsThePlainFile) {
    test::ScratchDir dir("io-csv-bom");
    const std::string sample = test::sourcePath("samples/deviations/multitasking-truth.csv");
    const std::string plain = test::readText(sample);
    std::string crlf;
    for (const char c : plain) crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
    test::writeText(dir.file("bom.csv"), "\xEF\xBB\xBF" + crlf);
    const DeviationSet want = readDeviationCsv(sample, test::multitasking());
    const DeviationSet got = readDeviationCsv(dir.file("bom.csv"), test::multitasking());
    ASSERT_EQ(got.values.size(), want.values.size());
    for (int i = 0; i < static_cast<int>(want.values.size()); ++i) EXPECT_DOUBLE_EQ(got.values[i], want.values[i]) << i;
}

// A comma-locale spreadsheet writes ';' between cells and decimal commas: read as meant. With ',' between cells a
// decimal comma cannot be told from a separator: the message says so.
TEST(DeviationCsvInput, SemicolonAndDecimalCommaAreReadOrNamed) {
    test::ScratchDir dir("io-csv-semicolon");
    test::writeText(dir.file("semi.csv"), "name;value;unit\nEX0C1;12,5;um\nEA0B;-4;arcsec\n");
    const DeviationSet d = readDeviationCsv(dir.file("semi.csv"), test::multitasking());
    EXPECT_NEAR(d.isoValue(test::multitasking().deviationIndex("EX0C1")), 12.5e-3, 1e-15);
    test::writeText(dir.file("comma.csv"), "name,value,unit\nEX0C1,12,5,um\n");
    const std::string e = inputErrorOf([&] { readDeviationCsv(dir.file("comma.csv"), test::multitasking()); });
    EXPECT_NE(e.find("comma.csv:2"), std::string::npos) << e;
    EXPECT_NE(e.find("decimal comma"), std::string::npos) << e;
    // A header the reader cannot use names what it found and the separator.
    test::writeText(dir.file("bad.csv"), "name|value|unit\nEX0C1|1|um\n");
    const std::string h = inputErrorOf([&] { readDeviationCsv(dir.file("bad.csv"), test::multitasking()); });
    EXPECT_NE(h.find("bad.csv:1"), std::string::npos) << h;
}

// Values beyond any machine (1e200 mm crashed `simulate` in the circle fit; 1e20..1e150 mm gave "collinear points")
// are refused at reading with the range.
TEST(DeviationCsvInput, ValuesBeyondAnyMachineAreRefusedWithTheRange) {
    test::ScratchDir dir("io-csv-range");
    for (const char* v : {"1e200,mm", "1e20,mm", "100.5,mm", "-2,deg", "7200,arcsec"}) {
        const std::string file = dir.file("r.csv");
        const bool angle = std::string(v).find("deg") != std::string::npos || std::string(v).find("arcsec") != std::string::npos;
        test::writeText(file, std::string("name,value,unit\n") + (angle ? "EA0B," : "EX0C1,") + v + "\n");
        const std::string e = inputErrorOf([&] { readDeviationCsv(file, test::multitasking()); });
        EXPECT_NE(e.find("r.csv:2"), std::string::npos) << v << ": " << e;
        EXPECT_NE(e.find(angle ? "3600 arcsec" : "100 mm"), std::string::npos) << v << ": " << e;
    }
    test::writeText(dir.file("ok.csv"), "name,value,unit\nEX0C1,99,mm\nEA0B,0.9,deg\n");
    EXPECT_NO_THROW(readDeviationCsv(dir.file("ok.csv"), test::multitasking()));
    // Through the CLI: exit 2 with the range, never a crash (exit 139 with --out oh).
    test::writeText(dir.file("huge.csv"), "name,value,unit\nEX0C1,1e200,mm\n");
    const auto r = test::runCli("simulate --machine " + test::sourcePath("samples/machines/multitasking.xml") + " --plan " +
                                test::sourcePath("samples/plans/multitasking-six-circles.xml") + " --deviations " +
                                dir.file("huge.csv") + " --out " + dir.file("oh"));
    EXPECT_EQ(r.exitCode, 2) << r.out;
    EXPECT_NE(r.out.find("100 mm"), std::string::npos) << r.out;
    EXPECT_FALSE(fs::exists(dir.file("oh")));
}

// Only regular files are read: a folder named like a trace is "a folder", a FIFO is refused without blocking.
TEST(CsvReader, OnlyRegularFilesAreRead) {
    test::ScratchDir dir("io-csv-regular");
    fs::create_directories(dir.file("B-X.csv"));
    std::string e = inputErrorOf([&] { readCsv(dir.file("B-X.csv")); });
    EXPECT_NE(e.find("is a folder, not a file"), std::string::npos) << e;
    EXPECT_EQ(e.find("empty file"), std::string::npos) << e;
    const std::string fifo = dir.file("B-Y.csv");
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    auto f = std::async(std::launch::async, [&] { return inputErrorOf([&] { readCsv(fifo); }); });
    if (f.wait_for(std::chrono::seconds(5)) == std::future_status::timeout) {
        ADD_FAILURE() << "reading a FIFO blocks";
        const int fd = ::open(fifo.c_str(), O_WRONLY);  // lets the blocked reader go on
        if (fd >= 0) ::close(fd);
    }
    e = f.get();
    EXPECT_NE(e.find("FIFO"), std::string::npos) << e;
    // The same for an XML input.
    e = inputErrorOf([&] { readPlanXml(fifo); });
    EXPECT_NE(e.find("FIFO"), std::string::npos) << e;
}

TEST(TextUtil, CommaItemsAreTrimmedAndEmptyOnesLeftOut) {
    // The one splitter of comma-list options (--report-controllers, --bounds, plan --lb/--candidates). Oracle: the
    // lists written out by hand.
    using V = std::vector<std::string>;
    EXPECT_EQ(io::commaItems("linuxcnc, fanuc-30i ,,siemens-840d,"), (V{"linuxcnc", "fanuc-30i", "siemens-840d"}));
    EXPECT_EQ(io::commaItems(""), V{});
    EXPECT_EQ(io::commaItems(" , ,"), V{});
    EXPECT_EQ(io::commaItems("EX0C=-5:5"), V{"EX0C=-5:5"});
    EXPECT_EQ(io::commaItems("\t360 ,410\t"), (V{"360", "410"}));
}

}  // namespace
}  // namespace cnccomp
