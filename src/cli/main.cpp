// The cnccomp command: thin dispatch over subcommands (cmd_*.cpp). Errors in the input end with exit code 2
// and a message naming the file and line.
#include <cstdio>
#include <exception>

#include <fmt/format.h>

#include "cli/command.hpp"
#include "cnccomp/error.hpp"
#include "cnccomp/version.hpp"

namespace cnccomp::cli {
std::vector<CommandSetup>& commandRegistry() {
    static std::vector<CommandSetup> registry;
    return registry;
}
}  // namespace cnccomp::cli

int main(int argc, char** argv) {
    CLI::App app{"cnccomp: identify, map and compensate geometric deviations of 5-axis and mill-turn machines"};
    app.set_version_flag("--version", fmt::format("cnccomp {}", cnccomp::kVersion), "print the version and exit");
    app.require_subcommand(1);
    for (const auto& setup : cnccomp::cli::commandRegistry()) setup(app);
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e);
    } catch (const cnccomp::InputError& e) {
        fmt::print(stderr, "cnccomp: error: {}\n", e.what());
        return 2;
    } catch (const cnccomp::ModelError& e) {
        fmt::print(stderr, "cnccomp: error: {}\n", e.what());
        return 2;
    } catch (const std::exception& e) {
        fmt::print(stderr, "cnccomp: error: {}\n", e.what());
        return 1;
    }
    return 0;
}
