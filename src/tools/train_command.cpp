// `ret3d train`: the parent of the training sub-subcommands (detector, and later intra / inter), which register
// themselves in trainRegistry() from their own files.
#include <algorithm>
#include <map>
#include <memory>

#include "tools/train_command.h"

#include "ret3d/detector/model_file.h"
#include "ret3d/eval/eval_data.h"
#include "ret3d/train/detector_outputs.h"

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
void DetectorSource::addOptions(CLI::App& app) {
  app.add_option("--detector", model,
                 "this package's detector model: run on --data's scans (boxes and features, cached in OUT.dets)");
  app.add_option("--detections-cache", cache, "with --detector: the cache file (default OUT.dets)");
  app.add_option("--score-threshold", score_threshold, "with --detector: its score threshold (default: the model's)");
}

io::SequenceDetections DetectorSource::run(const std::string& data, const std::string& sequences, int threads,
                                           const std::string& default_cache, const std::string& suffix) const {
  DetectorOptions det = detectorOptionsForModel(model);
  det.inference.threads = threads;
  if (score_threshold >= 0) det.inference.score_threshold = score_threshold;
  const std::vector<std::string> seqs =
      sequences.empty() ? std::vector<std::string>{} : eval::parseSequenceList(sequences);
  return train::detectSequences(data, seqs, det, (cache.empty() ? default_cache : cache) + suffix);
}

}  // namespace tools
}  // namespace ret3d
