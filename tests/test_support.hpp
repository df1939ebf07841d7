#pragma once
// Shared fixtures for the tests: sample paths, a scratch folder, running the CLI.
#include <filesystem>
#include <functional>
#include <string>

#include "cnccomp/io/machine_xml.hpp"

namespace cnccomp::test {

/// A file of the source tree / of ../shared (paths fixed at configure time, defined in test_support_impl.cpp only).
std::string sourcePath(const std::string& rel);
std::string sharedPath(const std::string& rel);
/// A sample machine, samples/machines/<stem>.xml, read once (the reference stays valid for the whole run).
const MachineModel& sampleMachine(const std::string& stem);
inline const MachineModel& multitasking() { return sampleMachine("multitasking"); }

/// A fresh empty folder under the system temp dir, removed at destruction.
struct ScratchDir {
    std::filesystem::path path;
    explicit ScratchDir(const std::string& tag);
    ~ScratchDir();
    std::string file(const std::string& name) const { return (path / name).string(); }
};

/// Writes `text` to a file.
void writeText(const std::string& path, const std::string& text);
std::string readText(const std::string& path);

/// The message of the exception `f` throws; "" when it throws none.
std::string errorOf(const std::function<void()>& f);
/// The message of the InputError `f` throws; "no InputError" when it throws none (another exception escapes).
std::string inputErrorOf(const std::function<void()>& f);

struct CliResult {
    int exitCode;
    std::string out;  ///< stdout and stderr together
};
/// Runs a shell command line (quoted by the caller), stdout and stderr together.
CliResult runCommand(const std::string& command);
/// Runs the cnccomp executable with `args` (shell-quoted by the caller).
CliResult runCli(const std::string& args);
/// Path of the cnccomp executable (for scripts that run it themselves).
std::string cliPath();

/// LinuxCNC's standalone interpreter rs274 (Debian linuxcnc-uspace), or "" when it is not installed.
std::string rs274Path();
/// The shell command that runs rs274 (`rs274Path()`) in batch mode on `ngc` with the tool table `tbl`, the canonical
/// calls to `out`, its messages to `log`, with HOME set to `home` (a test's own scratch folder): rs274 truncates and maps
/// $HOME/.tool.mmap, and two of them on one file (ctest -j2) end in SIGBUS ("Bus error", seen on a fresh clone's run).
std::string rs274Command(const std::string& home, const std::string& tbl, const std::string& ngc, const std::string& out,
                         const std::string& log);

}  // namespace cnccomp::test
