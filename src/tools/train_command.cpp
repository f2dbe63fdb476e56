// `ret3d train`: the parent of the training sub-subcommands (detector, and later intra / inter), which register
// themselves in trainRegistry() from their own files.
#include <algorithm>
#include <map>
#include <memory>

#include "tools/train_command.h"

namespace ret3d {
namespace tools {

std::vector<CommandInfo>& trainRegistry() {
  static std::vector<CommandInfo> registry;
  return registry;
}

namespace {

CommandRun setupTrain(CLI::App& app) {
  app.require_subcommand(1);
  auto& registry = trainRegistry();
  std::sort(registry.begin(), registry.end(), [](const auto& a, const auto& b) { return a.name < b.name; });
  auto runs = std::make_shared<std::map<CLI::App*, CommandRun>>();
  for (const auto& cmd : registry) {
    CLI::App* sub = app.add_subcommand(cmd.name, cmd.description);
    (*runs)[sub] = cmd.setup(*sub);
  }
  return [runs]() -> int {
    for (auto& [sub, run] : *runs)
      if (sub->parsed()) return run();
    return 1;
  };
}

CommandRegistrar reg("train", "train a learned stage (detector, ...) on KITTI-layout data", setupTrain);

}  // namespace
}  // namespace tools
}  // namespace ret3d
