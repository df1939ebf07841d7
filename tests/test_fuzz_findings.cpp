// Inputs found by the reader fuzz targets (tests/fuzz/), each reduced to what triggers it. Before the fix each
// one crashed or raised a sanitizer report; now the reader refuses it with an InputError naming the file and line (what
// the CLI reports as bad input, exit 2). Oracle: the reader's own contract (bad input → InputError), README "Tests".
#include <gtest/gtest.h>

#include <functional>
#include <sstream>

#include "cnccomp/error.hpp"
#include "postproc/klartext_reader.hpp"

namespace cnccomp {
namespace {

void expectInputError(const std::function<void()>& f, std::initializer_list<std::string> parts) {
    try {
        f();
        FAIL() << "no InputError";
    } catch (const InputError& e) {
        for (const std::string& p : parts) EXPECT_NE(std::string(e.what()).find(p), std::string::npos) << e.what() << "\nlacks: " << p;
    }
}

// Klartext target, -seed=1, input 'kt-crash-6e43a7d6…': a TOOL CALL number of 66 digits was converted to int
// (UBSan: "1e+66 is outside the range of representable values of type 'int'", klartext_blocks.cpp).
TEST(FuzzFindings, KlartextToolCallNumberOutOfRange) {
    for (const char* number : {"999999999999999999999999999999999999999999999999999999999999999991", "100001", "2.5"}) {
        std::istringstream in(std::string("0 BEGIN PGM ARC MM\n1 TOOL CALL ") + number + " Z\n2 L X+20 R0 FMAX\n3 END PGM ARC MM\n");
        std::ostringstream csv;
        postproc::PosesOptions o;
        o.inputName = "fuzz.h";
        expectInputError([&] { postproc::writeKlartextPoses(postproc::AxisLayout::generic(), in, csv, o); },
                         {"fuzz.h:2", "not a tool number"});
    }
    // The largest tool number is still read.
    std::istringstream in("0 BEGIN PGM T MM\n1 TOOL CALL 100000 Z\n2 L X+20 Y+0 Z+5 R0 FMAX\n3 END PGM T MM\n");
    std::ostringstream csv;
    postproc::PosesOptions o;
    EXPECT_NO_THROW(postproc::writeKlartextPoses(postproc::AxisLayout::generic(), in, csv, o));
}

}  // namespace
TEST(FuzzFindings, KlartextCycleNumberOutOfRange) {
    // ReaderFuzz_klartext: "CYCL DEF 4.44444e+39" overflowed the int cycle number (UBSan float-cast-overflow).
    for (const char* number : {"4444444444444444444444444444444444444444", "100000", "-7"}) {
        std::istringstream in(std::string("0 BEGIN PGM C MM\n1 CYCL DEF ") + number + " DATUM SHIFT\n2 END PGM C MM\n");
        std::ostringstream csv;
        postproc::PosesOptions o;
        o.inputName = "fuzz.h";
        expectInputError([&] { postproc::writeKlartextPoses(postproc::AxisLayout::generic(), in, csv, o); },
                         {"fuzz.h:2", "cycle number from 0 to 99999"});
    }
}

}  // namespace cnccomp
