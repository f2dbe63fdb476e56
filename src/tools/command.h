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

// The command as the user gave it ("ret3d train intra --data D --out M ..."), from the options CLI11 parsed: model
// files record it as their provenance.
inline std::string commandLine(const std::string& command, const CLI::App& app) {
  std::string line = command;
  for (const CLI::Option* o : app.get_options()) {
    if (o->count() == 0 || o->get_name() == "--help") continue;
    line += " " + o->get_name();
    if (o->get_type_size_max() == 0) continue;  // a flag
    for (const auto& r : o->results()) line += " " + r;
  }
  return line;
}

struct CommandRegistrar {
  CommandRegistrar(std::string name, std::string description, CommandSetup setup) {
    commandRegistry().push_back({std::move(name), std::move(description), std::move(setup)});
  }
};

}  // namespace tools
}  // namespace ret3d
