// Subcommands of the `ret3d` command line register themselves here, one file each (convert_command.cpp,
// sim_command.cpp, ...), so adding a subcommand touches no other file:
//
//   static ret3d::tools::CommandRegistrar reg("convert", "KITTI data to bags; bag checks", [](CLI::App& app) {
//     ... app.add_option(...); return [=]() -> int { ...; return 0; };
//   });
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace ret3d {
namespace tools {

// Returns the subcommand's exit code.
using CommandRun = std::function<int()>;
// Adds the subcommand's options to `app` (already created with its name and description) and returns what to run.
using CommandSetup = std::function<CommandRun(CLI::App& app)>;

struct CommandInfo {
  std::string name;
  std::string description;
  CommandSetup setup;
};

std::vector<CommandInfo>& commandRegistry();

struct CommandRegistrar {
  CommandRegistrar(std::string name, std::string description, CommandSetup setup) {
    commandRegistry().push_back({std::move(name), std::move(description), std::move(setup)});
  }
};

}  // namespace tools
}  // namespace ret3d
