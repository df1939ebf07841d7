// libFuzzer target: the HEIDENHAIN Klartext reader (writeKlartextPoses, postproc/klartext_reader.cpp, and the block
// interpreter postproc/klartext_blocks.cpp it shares with `cnccomp correct`) on the generic X Y Z A B C layout. Seeds:
// tests/fuzz/seeds/klartext/ (test programs written by `cnccomp testprog --dialect heidenhain`).
#include <sstream>

#include "fuzz_reader.hpp"
#include "postproc/klartext_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace cnccomp;
    static const postproc::AxisLayout layout = postproc::AxisLayout::generic();
    std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
    std::ostringstream csv;
    postproc::PosesOptions o;
    o.inputName = "fuzz.h";
    o.bufferSize = 256;  // overlong lines are exercised too
    fuzz::expectOnlyInputErrors([&] { (void)postproc::writeKlartextPoses(layout, in, csv, o); });
    return 0;
}
