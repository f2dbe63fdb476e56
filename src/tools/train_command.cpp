// `ret3d train`: the parent of the training sub-subcommands (detector, and later intra / inter), which register
// themselves in trainRegistry() from their own files.
#include <algorithm>
#include <map>
#include <memory>
#include <stdexcept>

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

void RelationTrainArgs::addOptions(CLI::App& app, const std::string& data_help, const std::string& detections_help,
                                    const std::string& config_help) {
  app.add_option("--data", data, data_help);
  app.add_option("--detections", detections, detections_help);
  detector.addOptions(app);
  app.add_option("--out", out, "model file to write");
  app.add_option("--config", config, config_help);
  app.add_option("--sequences", sequences, "training sequences, e.g. 1-15 (default: all labelled)");
  app.add_option("--val-sequences", val_sequences, "validation sequences: the best epoch's model is kept");
  app.add_option("--epochs", epochs, "override train.epochs");
  app.add_option("--threads", threads, "CPU threads for libtorch")->capture_default_str();
  app.add_option("--checkpoint", checkpoint, "checkpoint folder (default: OUT.ckpt)");
  app.add_flag("--resume", resume, "continue from the checkpoint");
  app.add_flag("--quiet", quiet, "no progress bar");
  app.add_option("--inspect", inspect, "print a model file's metadata and exit");
}

void RelationTrainArgs::validate() const {
  if (data.empty() || out.empty()) throw std::runtime_error("--data and --out are required");
  if (detections.empty() == !detector.given())
    throw std::runtime_error("give one of --detections DIR (another detector's results) or --detector MODEL");
}

io::SequenceDetections DetectorSource::run(const std::string& data, const std::string& sequences, int threads,
                                           const std::string& default_cache, const std::string& suffix) const {
  DetectorOptions det = detectorOptionsForModel(model);
  det.inference.threads = threads;
  if (score_threshold >= 0) det.inference.setScoreThreshold(static_cast<float>(score_threshold));
  const std::vector<std::string> seqs =
      sequences.empty() ? std::vector<std::string>{} : eval::parseSequenceList(sequences);
  return train::detectSequences(data, seqs, det, (cache.empty() ? default_cache : cache) + suffix);
}

}  // namespace tools
}  // namespace ret3d
