#pragma once
#include <string>

#include "cnccomp/machine.hpp"

namespace cnccomp::io {

/// Reads a machine description (see samples/machines/*.xml and the README). Throws InputError
/// with file:line on malformed XML, unknown attributes values or inconsistent chains.
MachineModel readMachineXml(const std::string& path);

}  // namespace cnccomp::io
