#include "test_support.hpp"

#include "cnccomp/error.hpp"

#include <array>
#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>
#include <random>
#include <sstream>
#include <sys/wait.h>

namespace cnccomp::test {
using namespace cnccomp::io;

std::string sourcePath(const std::string& rel) { return std::string(CNCCOMP_SOURCE_DIR) + "/" + rel; }
std::string sharedPath(const std::string& rel) { return std::string(CNCCOMP_SHARED_DIR) + "/" + rel; }

const MachineModel& sampleMachine(const std::string& stem) {
    static std::mutex lock;
    static std::map<std::string, std::unique_ptr<MachineModel>> cache;  // node-based: references stay valid
    const std::lock_guard<std::mutex> guard(lock);
    auto& m = cache[stem];
    if (!m) m = std::make_unique<MachineModel>(readMachineXml(sourcePath("samples/machines/" + stem + ".xml")));
    return *m;
}

ScratchDir::ScratchDir(const std::string& tag) {
    std::random_device rd;
    path = std::filesystem::temp_directory_path() / ("cnccomp-" + tag + "-" + std::to_string(rd()));
    std::filesystem::create_directories(path);
}
ScratchDir::~ScratchDir() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
}

void writeText(const std::string& path, const std::string& text) {
    std::ofstream(path, std::ios::binary) << text;
}

std::string errorOf(const std::function<void()>& f) {
    try {
        f();
    } catch (const std::exception& e) {
        return e.what();
    }
    return "";
}

std::string inputErrorOf(const std::function<void()>& f) {
    try {
        f();
    } catch (const InputError& e) {
        return e.what();
    }
    return "no InputError";
}

std::string readText(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

std::string cliPath() { return CNCCOMP_CLI; }

CliResult runCli(const std::string& args) { return runCommand(std::string(CNCCOMP_CLI) + " " + args); }

CliResult runCommand(const std::string& command) {
    const std::string cmd = command + " 2>&1";
    FILE* p = popen(cmd.c_str(), "r");
    CliResult r{-1, {}};
    if (!p) return r;
    std::array<char, 4096> buf;
    size_t n;
    while ((n = fread(buf.data(), 1, buf.size(), p)) > 0) r.out.append(buf.data(), n);
    const int status = pclose(p);
    r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return r;
}

std::string rs274Path() {
    for (const char* p : {"/usr/bin/rs274", "/usr/local/bin/rs274"})
        if (std::filesystem::exists(p)) return p;
    return {};
}

std::string rs274Command(const std::string& home, const std::string& tbl, const std::string& ngc, const std::string& out,
                         const std::string& log) {
    return "HOME='" + home + "' " + rs274Path() + " -t '" + tbl + "' -g '" + ngc + "' '" + out + "' < /dev/null > '" + log +
           "' 2>&1";
}

}  // namespace cnccomp::test
