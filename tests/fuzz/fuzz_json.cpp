// libFuzzer target: the one JSON reader (parseJson, src/cnccomp/io/json.cpp). Any input ends in a value or an
// InputError naming the line; never a crash, a hang or a stack overflow (nesting is limited). Seeds: tests/fuzz/seeds/json.
#include "cnccomp/io/json.hpp"
#include "fuzz_reader.hpp"
using namespace cnccomp::io;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace cnccomp;
    const std::string text(reinterpret_cast<const char*>(data), size);
    fuzz::expectOnlyInputErrors([&] { (void)parseJson(text, "fuzz.json"); });
    return 0;
}
