#pragma once
// Each subcommand lives in its own cmd_*.cpp and registers itself here: a setup function that adds a
// CLI11 subcommand with its options and callback. main() only dispatches.
#include <functional>
#include <vector>

#include <CLI/CLI.hpp>

namespace cnccomp::cli {

using CommandSetup = std::function<void(CLI::App&)>;
std::vector<CommandSetup>& commandRegistry();

struct RegisterCommand {
    explicit RegisterCommand(CommandSetup setup) { commandRegistry().push_back(std::move(setup)); }
};

}  // namespace cnccomp::cli
