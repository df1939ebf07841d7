// libFuzzer target: the machine description reader (readMachineXml, src/cnccomp/io/machine_xml.cpp). Seeds:
// samples/machines/*.xml. A reader may refuse only with InputError / ModelError (fuzz_reader.hpp).
#include "cnccomp/io/machine_xml.hpp"
#include "fuzz_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string path = cnccomp::fuzz::writeInput(data, size, ".xml");
    cnccomp::fuzz::expectOnlyInputErrors([&] { (void)cnccomp::io::readMachineXml(path); });
    return 0;
}
