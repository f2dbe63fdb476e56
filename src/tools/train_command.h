// `ret3d train <what>`: each learned stage adds its sub-subcommand from its own file, the same way subcommands
// register with `ret3d` (tools/command.h):
//
//   static ret3d::tools::TrainRegistrar reg("detector", "the LWD-3D base detector", [](CLI::App& app) {
//     ... app.add_option(...); return [=]() -> int { ...; return 0; };
//   });
#pragma once

#include <vector>

#include "tools/command.h"

namespace ret3d {
namespace tools {

std::vector<CommandInfo>& trainRegistry();

struct TrainRegistrar {
  TrainRegistrar(std::string name, std::string description, CommandSetup setup) {
    trainRegistry().push_back({std::move(name), std::move(description), std::move(setup)});
  }
};

}  // namespace tools
}  // namespace ret3d
