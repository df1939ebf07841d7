// libFuzzer target: the deviation file reader (readDeviationCsv, src/cnccomp/io/deviation_csv.cpp) against the
// multi-tasking machine (samples/machines/multitasking.xml) and the table-table machine. Seeds: samples/deviations/.
#include "cnccomp/io/deviation_csv.hpp"
#include "cnccomp/io/machine_xml.hpp"
#include "fuzz_reader.hpp"
using namespace cnccomp::io;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace cnccomp;
    static const MachineModel machines[] = {readMachineXml(CNCCOMP_SOURCE_DIR "/samples/machines/multitasking.xml"),
                                            readMachineXml(CNCCOMP_SOURCE_DIR "/samples/machines/table-table-ac.xml")};
    const std::string path = fuzz::writeInput(data, size, ".csv");
    for (const MachineModel& m : machines) fuzz::expectOnlyInputErrors([&] { (void)readDeviationCsv(path, m); });
    return 0;
}
