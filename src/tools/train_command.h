// `ret3d train <what>`: each learned stage adds its sub-subcommand from its own file, the same way subcommands
// register with `ret3d` (tools/command.h):
//
//   static ret3d::tools::TrainRegistrar reg("detector", "the LWD-3D base detector", [](CLI::App& app) {
//     ... app.add_option(...); return [=]() -> int { ...; return 0; };
//   });
#pragma once

#include <string>
#include <vector>

#include "ret3d/io/detection_cache.h"
#include "tools/command.h"

namespace ret3d {
namespace tools {

std::vector<CommandInfo>& trainRegistry();

struct TrainRegistrar {
  TrainRegistrar(std::string name, std::string description, CommandSetup setup) {
    trainRegistry().push_back({std::move(name), std::move(description), std::move(setup)});
  }
};

// The relation modules' training input from this package's detector (--detector MODEL): its boxes and features on
// the scans of a KITTI tracking folder, computed once and cached (train/detector_outputs.h).
struct DetectorSource {
  std::string model, cache;
  double score_threshold = -1;
  void addOptions(CLI::App& app);
  bool given() const { return !model.empty(); }
  // `sequences` in the --sequences syntax ("" = all); the cache file is <cache or default_cache><suffix>.
  io::SequenceDetections run(const std::string& data, const std::string& sequences, int threads,
                             const std::string& default_cache, const std::string& suffix) const;
};

}  // namespace tools
}  // namespace ret3d
