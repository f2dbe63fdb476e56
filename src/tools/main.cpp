// `ret3d`: the package's command line. Each subcommand lives in its own *_command.cpp and registers itself.
#include <algorithm>
#include <exception>
#include <iostream>
#include <map>

#include "tools/command.h"

namespace ret3d {
namespace tools {
std::vector<CommandInfo>& commandRegistry() {
  static std::vector<CommandInfo> registry;
  return registry;
}
}  // namespace tools
}  // namespace ret3d

int main(int argc, char** argv) {
  using namespace ret3d::tools;
  CLI::App app{"ret3d: LiDAR 3D object detection and tracking (LWD-3D + Ret3D) - offline tools"};
  app.require_subcommand(1);
  auto& registry = commandRegistry();
  std::sort(registry.begin(), registry.end(), [](const auto& a, const auto& b) { return a.name < b.name; });
  std::map<CLI::App*, CommandRun> runs;
  for (const auto& cmd : registry) {
    CLI::App* sub = app.add_subcommand(cmd.name, cmd.description);
    runs[sub] = cmd.setup(*sub);
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  for (auto& [sub, run] : runs) {
    if (sub->parsed()) {
      try {
        return run();
      } catch (const std::exception& e) {
        std::cerr << "ret3d " << sub->get_name() << ": error: " << e.what() << std::endl;
        return 1;
      }
    }
  }
  return 1;
}
