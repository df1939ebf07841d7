// libFuzzer target: the measurement plan reader (readPlanXml, src/cnccomp/io/plan_xml.cpp). Seeds: samples/plans/*.xml.
// A plan that reads is also formatted again (formatPlanXml) and read back: the writer must give a file the reader
// takes, with the same runs.
#include "cnccomp/io/plan_xml.hpp"
#include "fuzz_reader.hpp"
using namespace cnccomp::io;
using namespace cnccomp::measurement;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace cnccomp;
    const std::string path = fuzz::writeInput(data, size, ".xml");
    fuzz::expectOnlyInputErrors([&] {
        const MeasurementPlan plan = readPlanXml(path);
        const std::string text = formatPlanXml(plan);
        const std::string again = fuzz::writeInput(reinterpret_cast<const uint8_t*>(text.data()), text.size(), ".xml");
        MeasurementPlan back;
        try {
            back = readPlanXml(again);
        } catch (const std::exception& e) {
            std::fprintf(stderr, "cnccomp fuzz: a plan that read does not read back once written: %s\n", e.what());
            std::abort();
        }
        if (back.runCount() != plan.runCount()) std::abort();
    });
    return 0;
}
