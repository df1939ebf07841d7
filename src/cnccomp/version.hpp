#pragma once
// The program's version, printed by `cnccomp --version` (kept equal to project(VERSION) in CMakeLists.txt; a test
// checks that they agree).
namespace cnccomp {
inline constexpr const char* kVersion = "0.1.0";
}  // namespace cnccomp
