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

// What `ret3d train intra` and `ret3d train inter` share: the data and the boxes to refine (another detector's
// results or this package's detector), the output and checkpoint, the schedule, and --inspect.
struct RelationTrainArgs {
  std::string data, detections, out, config, sequences, val_sequences, checkpoint, inspect;
  DetectorSource detector;
  int epochs = -1, threads = 2;
  bool resume = false, quiet = false;
  std::string command_line;  // stored in the model file

  // The help of --data, --detections and --config names what the module reads.
  void addOptions(CLI::App& app, const std::string& data_help, const std::string& detections_help,
                  const std::string& config_help);
  // Throws std::runtime_error unless --data and --out are given with exactly one source of boxes.
  void validate() const;
};

}  // namespace tools
}  // namespace ret3d
