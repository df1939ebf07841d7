// libFuzzer target: the instrument file import (importRunTrace / importTrace, src/cnccomp/io/trace_import.cpp), each
// input read as a time-sampled file of a C-radial run recorded CW then CCW, as an angle-sampled file of the same run,
// and as a file without a run. Seeds: tests/fuzz/seeds/trace/, small files of that run (15° step) in the layouts the
// import takes (README "Measured ball-bar data"): angle-sampled with `# key: value` metadata; time-sampled CW then CCW
// with a pass column, 4° overshoot and a missing sample; time-sampled with ';', decimal comma, CRLF and a byte-order
// mark. Their ΔL values are made up (sines of a few um): the fuzz target checks the reader, not the numbers.
#include "cnccomp/io/trace_import.hpp"
#include "fuzz_reader.hpp"
using namespace cnccomp::io;

namespace {
cnccomp::BallbarRun cRadial(bool timeSampled) {
    cnccomp::BallbarRun r;
    r.name = "C-radial";
    r.test = cnccomp::BallbarTest::CRadial;
    r.LB = 100;
    r.RB = 360;
    r.RC = 50;
    r.ZC = 300;
    r.startDeg = 0;
    r.endDeg = 360;
    r.stepDeg = 15;
    if (timeSampled) {
        r.capture.feed = 1000;
        r.capture.overshootDeg = 4;
        r.capture.passes = {-1, +1};
    }
    return r;
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace cnccomp;
    static const BallbarRun timeRun = cRadial(true), angleRun = cRadial(false);
    const std::string path = fuzz::writeInput(data, size, ".csv");
    fuzz::expectOnlyInputErrors([&] { (void)importRunTrace(path, timeRun, "multitasking"); });
    fuzz::expectOnlyInputErrors([&] { (void)importRunTrace(path, angleRun); });
    fuzz::expectOnlyInputErrors([&] { (void)importTrace(path); });
    return 0;
}
